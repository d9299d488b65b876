//! Examples of embedding Gnomon in another program, each a file in this folder:
//!
//! - `headless.rs`: render a glTF file to a PNG through the library, with no window.
//! - `window.rs`: a winit application with its own mesh, camera and WGSL shader,
//!   which asks Gnomon for its light's shadows and calls `shadow_visibility` from its
//!   own fragment shader ([`host`]).
//! - `virtual_pages.rs`: the pages a virtual shadow map would draw for one view,
//!   from the library's page-request pass on the surfaces the renderer saw.
//!
//! Run one with `cargo run --release -p gnomon-examples --example headless -- FILE.gltf OUT.png`
//! or `cargo run --release -p gnomon-examples --example window`.
//! `.ci/run` runs the headless one on `data/box-on-ground.gltf`, a box on a ground
//! plane, and the window one under Xvfb for a few frames.

pub mod host;

/// The guide's pages with Rust in them, compiled by `cargo test` as doctests, so that
/// no example a reader copies has rotted. Each block is `rust,no_run`: compiled, not
/// run (the tests that run the same calls are named beside each block).
/// [`tests::every_page_with_rust_is_compiled`] fails when a page gains a Rust block
/// without being listed here.
#[cfg(doctest)]
pub mod guide {
    #[doc = include_str!("../README.md")]
    pub struct Readme;
    #[doc = include_str!("../docs/library.md")]
    pub struct Library;
    #[doc = include_str!("../docs/rays-tracers.md")]
    pub struct RaysTracers;
}

/// The pages `guide` compiles, as paths from the repository's root.
pub const COMPILED_PAGES: &[&str] = &["README.md", "docs/library.md", "docs/rays-tracers.md"];

#[cfg(test)]
mod tests {
    use std::path::Path;

    /// Every Markdown page of the repository that holds a Rust block is one that
    /// `guide` compiles (a block in a page left out would never be built).
    #[test]
    fn every_page_with_rust_is_compiled() {
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
        let mut pages = vec![root.join("README.md"), root.join("CHANGELOG.md")];
        for entry in std::fs::read_dir(root.join("docs")).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "md") {
                pages.push(path);
            }
        }
        let mut with_rust = Vec::new();
        for page in &pages {
            let text = std::fs::read_to_string(page).unwrap();
            // An opening fence of Rust, or one with no language, which rustdoc takes
            // for Rust too.
            let mut open = false;
            for line in text.lines().filter(|l| l.starts_with("```")) {
                if !open && (line.starts_with("```rust") || line.trim() == "```") {
                    with_rust.push(page.strip_prefix(&root).unwrap().to_string_lossy().into_owned());
                }
                open = !open;
            }
        }
        with_rust.sort();
        with_rust.dedup();
        for page in &with_rust {
            assert!(
                super::COMPILED_PAGES.contains(&page.as_str()),
                "{page} has Rust blocks that no doctest compiles"
            );
        }
        assert!(with_rust.len() >= 3, "the scan found {with_rust:?}");
    }
}
