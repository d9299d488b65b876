//! Where a pass binds a resource that one WGSL file declares for every pass that
//! reads it (the light, the camera, the material texture, the shadow resources).

/// Where a pass binds a resource that one WGSL file declares for every pass that
/// reads it: the file reads the place as generated constants (`LIGHT_GROUP`,
/// `LIGHT_BINDING`), so each declaration is written once and no pass picks it by
/// which file it was composed with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct BindingPlace {
    /// The bind group's index.
    pub group: u32,
    /// The binding of the file's first resource; the others follow it in order.
    pub binding: u32,
}

impl BindingPlace {
    /// `declaration`, whose bindings read `{name}_GROUP` and `{name}_BINDING`, placed here.
    pub(crate) fn declare(self, name: &str, declaration: &str) -> String {
        format!(
            "const {name}_GROUP: u32 = {}u;\nconst {name}_BINDING: u32 = {}u;\n{declaration}",
            self.group, self.binding
        )
    }
}
