//! Where a pass binds a resource that one WGSL module declares for every pass that
//! reads it (the light, the camera, the material texture, the shadow resources).

/// Where a pass binds a resource that one WGSL module declares for every pass that
/// reads it: the module imports the place as generated constants (`LIGHT_GROUP`,
/// `LIGHT_BINDING` from `package::variant`), so each declaration is written once and
/// each pass places it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct BindingPlace {
    /// The bind group's index.
    pub group: u32,
    /// The binding of the file's first resource; the others follow it in order.
    pub binding: u32,
}

impl BindingPlace {
    /// The generated constants `{name}_GROUP` and `{name}_BINDING` that place the
    /// declaration whose bindings read them here.
    pub(crate) fn declare(self, name: &str) -> String {
        format!(
            "const {name}_GROUP: u32 = {}u;\nconst {name}_BINDING: u32 = {}u;\n",
            self.group, self.binding
        )
    }
}
