//! Where the viewer's status lines go besides its status bar: standard error on the
//! desktop, the browser's console in a page, each prefixed `gnomon view:`.

/// Writes one status line out.
pub(crate) fn say(message: &str) {
    #[cfg(not(target_arch = "wasm32"))]
    eprintln!("gnomon view: {message}");
    #[cfg(target_arch = "wasm32")]
    web_sys::console::log_1(&format!("gnomon view: {message}").into());
}
