//! Links a shader from the renderer's WGSL modules with WESL (`wesl`; its imports:
//! <https://github.com/wgsl-tooling-wg/wesl-spec/blob/main/Imports.md>).
//!
//! Every `.wgsl` file under `src/` is a module, `package::<folder>::<file>`
//! (`src/passes/light.wgsl` is `package::passes::light`; `build.rs` lists them), and
//! imports each name it uses from the module that declares it. Two modules are
//! generated: `package::constants`, the limits and codes generated from Rust
//! ([`super::generated::wgsl_constants`]), the same in every shader; and
//! `package::variant`, what one shader chooses: the interfaces bound to their
//! implementations (`passes::wgsl_interfaces`), the technique's parameter type, the
//! binding places, the Poisson disk and the passes' own generated constants.
//!
//! A pass hands [`super::compose_wgsl`] its parts: a part that is a module's text
//! (`include_str!` of it) loads that module, and with it everything it imports; any
//! other part is generated and goes into `package::variant`, which imports what it
//! names, and which every shader loads. The link keeps every declaration of every module loaded (`strip: false`),
//! as concatenating the same files did, and no name is mangled (`NoMangler`): no two
//! modules declare one name (`scripts/wgsl-duplicates.py`), so entry points, structs
//! and the layout test's names stay as written.

use std::{
    borrow::Cow,
    collections::{BTreeSet, HashMap},
    sync::OnceLock,
};

use wesl::{
    CompileOptions, EscapeMangler, NoMangler, VirtualResolver,
    syntax::{ModulePath, PathOrigin, TranslationUnit},
};
use wgsl_parse::SyntaxNode as _;

/// One `.wgsl` file of the renderer as a WESL module.
pub(crate) struct WgslModule {
    /// Its module path under `package`, `passes::light`.
    pub path: &'static str,
    /// Its text.
    pub source: &'static str,
}

/// Every `.wgsl` file under `src/`, listed by `build.rs`.
pub(crate) const MODULES: &[WgslModule] = include!(concat!(env!("OUT_DIR"), "/wgsl_modules.rs"));

/// The module of constants generated from Rust, the same for every shader.
pub(crate) const CONSTANTS_MODULE: &str = "constants";
/// The module of what one shader chooses, generated per shader.
pub(crate) const VARIANT_MODULE: &str = "variant";
/// The generated root, which imports the modules a pass names.
const ROOT_MODULE: &str = "root";

/// What the linker knows of the modules, read once.
struct Library {
    /// A module's path, by its text.
    path_of_source: HashMap<&'static str, &'static str>,
    /// The module that declares each top-level name, the constants' included.
    home: HashMap<String, &'static str>,
    /// A name each module declares, which the root imports to load the module.
    first_name: HashMap<&'static str, String>,
    /// `package::constants`' text.
    constants: String,
}

/// The names `source` declares at module scope, in order.
pub(crate) fn declared_names(source: &str) -> Result<Vec<String>, String> {
    let unit: TranslationUnit = source.parse().map_err(|e| format!("{e}"))?;
    Ok(unit
        .global_declarations
        .iter()
        .filter_map(|d| d.ident().map(|ident| ident.name().to_string()))
        .collect())
}

impl Library {
    /// What the linker knows of `modules`, with `package::constants`.
    fn new(modules: &[WgslModule]) -> Library {
        let constants = super::generated::wgsl_constants();
        let mut library = Library {
            path_of_source: HashMap::new(),
            home: HashMap::new(),
            first_name: HashMap::new(),
            constants: constants.clone(),
        };
        // The renderer's own files parse: `interface_tests` links every shader.
        for name in declared_names(&constants).unwrap_or_default() {
            library.home.insert(name, CONSTANTS_MODULE);
        }
        for module in modules {
            let names = declared_names(module.source).unwrap_or_default();
            if let Some(first) = names.first() {
                library.first_name.insert(module.path, first.clone());
            }
            for name in names {
                library.home.insert(name, module.path);
            }
            library.path_of_source.insert(module.source, module.path);
        }
        library
    }
}

/// The renderer's modules, read once.
fn library() -> &'static Library {
    static LIBRARY: OnceLock<Library> = OnceLock::new();
    LIBRARY.get_or_init(|| Library::new(MODULES))
}

/// `text` without `//` comments.
fn without_comments(text: &str) -> String {
    text.lines().map(|line| line.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n")
}

/// The identifiers of generated WGSL, as `(used, declared)`: a name is declared
/// where it follows `fn`, `struct`, `alias`, `const`, `var` or `let`, or precedes
/// `:` (a parameter, a field, or `var<private> name:`), and used anywhere else but
/// after `.` (a member).
/// Generated text is regular enough for this; the modules themselves import by hand.
fn identifiers(text: &str) -> (BTreeSet<String>, BTreeSet<String>) {
    const DECLARING: [&str; 6] = ["fn", "struct", "alias", "const", "var", "let"];
    let code = without_comments(text);
    let bytes = code.as_bytes();
    let (mut used, mut declared) = (BTreeSet::new(), BTreeSet::new());
    let mut previous_word = String::new();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_alphabetic() || c == b'_' {
            let start = i;
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'_') {
                i += 1;
            }
            let word = &code[start..i];
            let before = code[..start].trim_end();
            let after = code[i..].trim_start();
            let is_decl = DECLARING.contains(&previous_word.as_str())
                || (after.starts_with(':') && !after.starts_with("::"));
            if is_decl {
                declared.insert(word.to_owned());
            } else if !before.ends_with('.') {
                used.insert(word.to_owned());
            }
            previous_word = word.to_owned();
        } else if c.is_ascii_digit() {
            while i < bytes.len() && (bytes[i].is_ascii_alphanumeric() || bytes[i] == b'.') {
                i += 1;
            }
        } else {
            if !c.is_ascii_whitespace() {
                previous_word.clear();
            }
            i += 1;
        }
    }
    (used, declared)
}

/// `package::variant`: the generated parts, after the imports of the names they use
/// that a module declares.
fn variant_module(library: &Library, generated: &[&str]) -> String {
    let text = generated.join("\n");
    let (used, declared) = identifiers(&text);
    let mut imports: Vec<(&str, &str)> = used
        .iter()
        .filter(|name| !declared.contains(*name))
        .filter_map(|name| library.home.get(name).map(|home| (*home, name.as_str())))
        .collect();
    imports.sort();
    let mut module: String =
        imports.iter().map(|(home, name)| format!("import package::{home}::{name};\n")).collect();
    module += &text;
    module
}

/// `package::{path}`, for a path of `::`-separated names.
pub(crate) fn module_path(path: &str) -> ModulePath {
    ModulePath::new(PathOrigin::Absolute, path.split("::").map(str::to_owned).collect())
}

/// How a link names the declarations it keeps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Naming {
    /// As the modules write them (`NoMangler`): what every shader uses.
    AsWritten,
    /// Prefixed by their module's path (`EscapeMangler`): a name that a module uses
    /// without importing it is then declared under another name, and naga refuses
    /// the shader. `passes::interface_tests` links every shader so.
    #[cfg_attr(not(test), expect(dead_code, reason = "the interface tests' check of every module's imports"))]
    ByModule,
}

/// Links `parts` into one WGSL shader: the modules whose text they are, everything
/// those import, and `package::variant` made of the others (see the module's
/// documentation). A part is the text of a module or generated WGSL.
pub(crate) fn link(parts: &[&str], naming: Naming) -> Result<String, String> {
    link_from(library(), MODULES, parts, naming)
}

fn link_from(
    library: &Library,
    modules: &[WgslModule],
    parts: &[&str],
    naming: Naming,
) -> Result<String, String> {
    let mut roots: Vec<&'static str> = Vec::new();
    let mut generated: Vec<&str> = Vec::new();
    for part in parts {
        match library.path_of_source.get(part) {
            Some(path) if !roots.contains(path) => roots.push(path),
            Some(_) => {}
            None => generated.push(part),
        }
    }
    let variant = variant_module(library, &generated);
    // The root loads the variant too, so that every generated part is in the
    // shader (and checked) whether or not a module imports it, as with the modules.
    let variant_names = declared_names(&variant)
        .map_err(|e| format!("the generated WGSL of `package::{VARIANT_MODULE}` does not parse: {e}"))?;
    let root: String = roots
        .iter()
        .filter_map(|path| library.first_name.get(path).map(|name| (*path, name)))
        .chain(variant_names.first().map(|name| (VARIANT_MODULE, name)))
        .map(|(path, name)| format!("import package::{path}::{name};\n"))
        .collect();
    let mut resolver = VirtualResolver::new();
    for module in modules {
        resolver.add_module(module_path(module.path), Cow::Borrowed(module.source));
    }
    resolver.add_module(module_path(CONSTANTS_MODULE), Cow::Borrowed(library.constants.as_str()));
    resolver.add_module(module_path(VARIANT_MODULE), Cow::Owned(variant));
    resolver.add_module(module_path(ROOT_MODULE), Cow::Owned(root));
    // Keep every declaration of every module loaded, as concatenation did; naga
    // validates the result, so WESL's own partial checks are off.
    let options = CompileOptions { strip: false, lazy: false, validate: false, ..CompileOptions::default() };
    let root = module_path(ROOT_MODULE);
    let linked = match naming {
        Naming::AsWritten => wesl::compile(&root, &resolver, &NoMangler, &options),
        Naming::ByModule => wesl::compile(&root, &resolver, &EscapeMangler, &options),
    };
    linked.map(|linked| linked.to_string()).map_err(|e| without_ansi_styles(&e.to_string()))
}

/// `text` without the terminal's colour codes (`ESC [ … m`) that WESL's diagnostics
/// carry, so that an error reads the same in a log, a file or a shader comment.
fn without_ansi_styles(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut chars = text.chars();
    while let Some(c) = chars.next() {
        if c == '\u{1b}' {
            // Skip to the end of the escape sequence, its final letter.
            for c in chars.by_ref() {
                if c.is_ascii_alphabetic() {
                    break;
                }
            }
        } else {
            out.push(c);
        }
    }
    out
}

#[cfg(test)]
thread_local! {
    /// How [`super::compose_wgsl`] names declarations on this thread: a test may ask
    /// for [`Naming::ByModule`] to check the modules' imports.
    pub(crate) static TEST_NAMING: std::cell::Cell<Naming> = const { std::cell::Cell::new(Naming::AsWritten) };
}

#[cfg(test)]
mod tests {
    use wgpu::naga;

    use super::*;

    /// `scene_common.wgsl` (which samples the material texture of
    /// `material_bindings.wgsl`) linked with its material placed, as naga parses it.
    fn parse_scene_common(source: &'static str, naming: Naming) -> Result<naga::Module, String> {
        let modules: Vec<WgslModule> = MODULES
            .iter()
            .map(|m| WgslModule {
                path: m.path,
                source: if m.path == "passes::scene_common" { source } else { m.source },
            })
            .collect();
        let library = Library::new(&modules);
        // The material's module is named too, so that the link as written has it
        // whether or not `scene_common.wgsl` imports it.
        let material =
            MODULES.iter().find(|m| m.path == "passes::material_bindings").expect("a module").source;
        let place = crate::passes::material_bindings_wgsl(crate::passes::CAMERA_MATERIAL_BINDINGS);
        let linked = link_from(&library, &modules, &[source, material, &place], naming)?;
        naga::front::wgsl::parse_str(&linked).map_err(|e| e.emit_to_string(&linked))
    }

    /// A module that uses a name it does not import links by module path into a
    /// shader naga refuses; as written, it would have linked, which is why the
    /// interface test links by module.
    #[test]
    fn a_missing_import_fails_the_link_by_module() {
        let original = crate::passes::SCENE_COMMON_WGSL;
        assert!(
            original.contains("import package::passes::material_bindings::"),
            "the import this test removes"
        );
        let without: String = original
            .lines()
            .filter(|l| !l.starts_with("import package::passes::material_bindings::"))
            .map(|l| format!("{l}\n"))
            .collect();
        let without: &'static str = Box::leak(without.into_boxed_str());
        parse_scene_common(original, Naming::ByModule).expect("the module as written links by module");
        parse_scene_common(without, Naming::AsWritten).expect("as written, a missing import goes unseen");
        let error = parse_scene_common(without, Naming::ByModule).expect_err("a missing import must fail");
        assert!(error.contains("base_color"), "{error}");
    }

    #[test]
    fn an_error_loses_its_colour_codes() {
        assert_eq!(without_ansi_styles("\u{1b}[1m\u{1b}[94m= \u{1b}[0mnote"), "= note");
    }

    /// A part that does not parse is an error naming what is wrong, not a panic.
    #[test]
    fn a_part_that_does_not_parse_is_an_error() {
        let error = link(&["fn broken( -> f32 {"], Naming::AsWritten).expect_err("not WGSL");
        assert!(error.contains("package::variant") && error.contains("does not parse"), "{error}");
    }

    /// The generated part's names resolve by import, not by a declaration in the part.
    #[test]
    fn the_variant_imports_what_its_generated_parts_name() {
        let library = library();
        let variant = variant_module(
            library,
            &[
                "fn lookup_visibility(world: vec3<f32>, q: ShadowQuery) -> f32 { let light = 1.0; return map_lookup(world, light); }",
            ],
        );
        assert!(variant.contains("import package::techniques::common::ShadowQuery;"), "{variant}");
        // A parameter or a local of the name of a module's declaration is not imported.
        assert!(!variant.contains("::light;"), "{variant}");
        assert!(!variant.contains("::world;"), "{variant}");
    }
}
