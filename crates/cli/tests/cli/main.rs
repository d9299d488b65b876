//! The `gnomon` binary's tests, as one test binary: each module runs the command
//! line on one topic; `support` holds what they share.

mod support;

mod bench_sun;
mod calibrate;
mod commands;
mod hardening;
mod rays;
mod surfaces;
