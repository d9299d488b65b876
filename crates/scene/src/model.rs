//! The scene model: what the renderer draws and what the reference ray tracer traces.

use glam::{Mat4, Vec2, Vec3};
use gnomon_math::Aabb;

use crate::{DirectionalLight, Falloff, Light, PointLight, SceneError, SceneLight, SpotLight};

/// A triangle mesh in object space. Triangles are counter-clockwise when seen from
/// the side their normals point to.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Mesh {
    /// The mesh's name, for error messages (from the glTF mesh, or given by a built-in scene).
    pub name: String,
    /// Vertex positions in object space.
    pub positions: Vec<Vec3>,
    /// Vertex normals in object space, one per position.
    pub normals: Vec<Vec3>,
    /// Vertex texture coordinates (u right, v down, as glTF), one per position.
    pub uvs: Vec<Vec2>,
    /// Triangle list: three indices into the vertex arrays per triangle.
    pub indices: Vec<u32>,
}

impl Mesh {
    /// Number of triangles, `indices.len() / 3`.
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Object-space bounds of the positions; [`Aabb::EMPTY`] for a mesh without vertices.
    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(self.positions.iter().copied())
    }
}

/// How a material's alpha is used (glTF 2.0 `alphaMode`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum AlphaMode {
    /// Alpha is ignored: the surface is solid.
    Opaque,
    /// The surface exists where alpha ≥ the cutoff, and nowhere else: cut-out leaves,
    /// fences. Shadows are cut out the same way.
    Mask {
        /// The alpha threshold, in [0, 1] (glTF `alphaCutoff`, 0.5 when absent).
        cutoff: f32,
    },
    /// Partly transparent. Gnomon draws it solid in the image but it casts no
    /// shadow: a shadow map stores one depth, and no threshold is right for glass.
    Blend,
}

/// A surface's appearance for the lighting pass (Lambert + Blinn-Phong).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// The material's name, for error messages.
    pub name: String,
    /// Linear RGB base colour (albedo), each channel in [0, 1].
    pub base_color: Vec3,
    /// Base alpha, multiplied with the texture's alpha.
    pub alpha: f32,
    /// Base-colour texture: an index into [`Scene::textures`], multiplied with `base_color`.
    pub base_color_texture: Option<usize>,
    /// How alpha decides where the surface exists, and whether it casts shadows.
    pub alpha_mode: AlphaMode,
    /// Whether both sides are meant to be seen (glTF `doubleSided`).
    pub double_sided: bool,
    /// Weight of the Blinn-Phong highlight.
    pub specular: f32,
    /// Blinn-Phong exponent.
    pub shininess: f32,
}

impl Material {
    /// An opaque, single-sided, untextured material of colour `base_color` (linear RGB) with a
    /// moderate highlight (specular 0.25, shininess 48).
    pub fn new(name: &str, base_color: Vec3) -> Self {
        Self {
            name: name.into(),
            base_color,
            alpha: 1.0,
            base_color_texture: None,
            alpha_mode: AlphaMode::Opaque,
            double_sided: false,
            specular: 0.25,
            shininess: 48.0,
        }
    }
}

/// How a texture coordinate outside [0, 1] wraps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Wrap {
    /// Coordinates wrap around: the texture tiles (glTF `REPEAT`).
    Repeat,
    /// The texture tiles, mirrored on every other repeat (glTF `MIRRORED_REPEAT`).
    MirroredRepeat,
    /// Coordinates are clamped to [0, 1]: the edge texels stretch outward (glTF `CLAMP_TO_EDGE`).
    ClampToEdge,
}

/// An RGBA8 texture in memory (colour channels sRGB-encoded, alpha linear), with its sampler.
#[derive(Clone, Debug, PartialEq)]
pub struct Texture {
    /// The texture's name, for error messages.
    pub name: String,
    /// Width in texels.
    pub width: u32,
    /// Height in texels.
    pub height: u32,
    /// Texels row by row from the top row (v = 0), four bytes each (R, G, B, A):
    /// `4 · width · height` bytes in all.
    pub rgba8: Vec<u8>,
    /// Wrapping along u (horizontally).
    pub wrap_u: Wrap,
    /// Wrapping along v (vertically).
    pub wrap_v: Wrap,
    /// Nearest-texel magnification (glTF `NEAREST`); otherwise bilinear.
    pub nearest: bool,
}

/// One placed copy of a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// The instance's name, for error messages (the glTF node, or given by a built-in scene).
    pub name: String,
    /// The mesh drawn: an index into [`Scene::meshes`].
    pub mesh: usize,
    /// The material it is drawn with: an index into [`Scene::materials`].
    pub material: usize,
    /// Object space to world space: where the instance is placed, turned and scaled.
    pub world_from_object: Mat4,
    /// Whether the instance is drawn into shadow maps. Every instance receives shadows.
    pub casts_shadow: bool,
    /// Whether it is expected to move: what a shadow map's cache of still casters
    /// leaves out.
    pub motion: Motion,
}

/// Whether an instance is expected to move, frame after frame.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "kebab-case")]
pub enum Motion {
    /// It stays where the scene placed it. Shadow maps keep it in their cache of still
    /// casters, and draw it again only when the light, the layer or such an instance
    /// changes. It may still be moved (`Renderer::move_instances`), at the cost of
    /// those redraws.
    #[default]
    Static,
    /// It may move in any frame: shadow maps draw it over their cached still casters
    /// every frame.
    Dynamic,
}

/// A perspective camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Camera position in world space.
    pub eye: Vec3,
    /// World-space point the camera looks at; the view direction is `target − eye`.
    pub target: Vec3,
    /// World-space up hint that fixes the roll (+y everywhere in Gnomon); need not be
    /// perpendicular to the view direction, but must not be parallel to it.
    pub up: Vec3,
    /// Full vertical field of view, in degrees.
    pub fov_y_degrees: f32,
    /// Near plane distance along the view direction, in world units; depth 0 in clip space.
    pub near: f32,
    /// Far plane distance along the view direction, in world units; depth 1 in clip space.
    pub far: f32,
}

impl Camera {
    /// World space to the camera's view space (right-handed, looking down −z).
    pub fn view_from_world(&self) -> Mat4 {
        gnomon_math::view_from_world_look_at(self.eye, self.target, self.up)
    }

    /// View space to clip space for an image of `aspect` = width / height: a perspective
    /// projection with WebGPU depth in [0, 1] from `near` to `far`.
    pub fn clip_from_view(&self, aspect: f32) -> Mat4 {
        gnomon_math::camera_clip_from_view(self.fov_y_degrees.to_radians(), aspect, self.near, self.far)
    }

    /// World space to clip space: `clip_from_view(aspect) · view_from_world()`.
    pub fn clip_from_world(&self, aspect: f32) -> Mat4 {
        self.clip_from_view(aspect) * self.view_from_world()
    }
}

/// Direction *toward* the sun for an elevation above the horizon and an azimuth
/// measured from +z toward +x, both in degrees.
pub fn sun_direction(elevation_degrees: f32, azimuth_degrees: f32) -> Vec3 {
    let (el, az) = (elevation_degrees.to_radians(), azimuth_degrees.to_radians());
    Vec3::new(el.cos() * az.sin(), el.sin(), el.cos() * az.cos())
}

/// A complete scene with its default view and lights.
#[derive(Clone, Debug)]
pub struct Scene {
    /// The scene's name: the built-in's, or taken from its file; shown in reports and error messages.
    pub name: String,
    /// Every mesh, in object space; instances refer to them by index.
    pub meshes: Vec<Mesh>,
    /// Every material; instances refer to them by index.
    pub materials: Vec<Material>,
    /// The placed meshes: what is drawn and traced.
    pub instances: Vec<Instance>,
    /// The default view, which the settings' camera overrides change.
    pub camera: Camera,
    /// Every light: the listed ones (`--light all`), each with its own shadow
    /// settings, and each kind's default (`--light sun`, …); [`crate::scene_lights`]
    /// holds the rule that picks a kind's light, [`Scene::light`].
    pub lights: Vec<SceneLight>,
    /// Linear RGB ambient light, added unshadowed.
    pub ambient: Vec3,
    /// Textures referred to by materials.
    pub textures: Vec<Texture>,
    /// Whether the scene has a floor to catch shadows (the built-ins do; a glTF
    /// model gets one from [`Scene::add_ground_plane`]).
    pub has_ground: bool,
}

impl Scene {
    /// An empty scene seen by `camera` and lit by `sun`, for a program that keeps its
    /// own geometry to hand its shadow casters to Gnomon with [`Scene::place`]. Its
    /// default spot and point light (used only when settings pick them) hang 10 units
    /// above the origin, the spot pointing down.
    pub fn new(name: &str, camera: Camera, sun: DirectionalLight) -> Scene {
        let above = Vec3::new(0.0, 10.0, 0.0);
        let white = Vec3::ONE;
        Scene {
            name: name.into(),
            meshes: Vec::new(),
            materials: Vec::new(),
            instances: Vec::new(),
            camera,
            lights: vec![
                SceneLight::default_of_kind(sun),
                SceneLight::default_of_kind(SpotLight {
                    position: above,
                    direction: Vec3::NEG_Y,
                    inner_angle_degrees: 32.0,
                    outer_angle_degrees: 40.0,
                    range: 30.0,
                    color: white,
                    intensity: 1.0,
                    falloff: Falloff::Constant,
                    radius: 0.0,
                }),
                SceneLight::default_of_kind(PointLight {
                    position: above,
                    range: 30.0,
                    color: white,
                    intensity: 1.0,
                    falloff: Falloff::Constant,
                    radius: 0.0,
                }),
            ],
            ambient: Vec3::splat(0.12),
            textures: Vec::new(),
            has_ground: false,
        }
    }

    /// Adds `mesh` with `material` at `world_from_object`, casting shadows.
    pub fn place(&mut self, name: &str, mesh: Mesh, material: Material, world_from_object: Mat4) {
        self.meshes.push(mesh);
        self.materials.push(material);
        self.instances.push(Instance {
            name: name.into(),
            mesh: self.meshes.len() - 1,
            material: self.materials.len() - 1,
            world_from_object,
            casts_shadow: true,
            motion: crate::Motion::Static,
        });
    }

    /// World-space bounds of all instances.
    pub fn bounds(&self) -> Aabb {
        // Each mesh's bounds once, not once per instance: a million instances of a
        // few meshes must not walk a million vertex lists.
        let mesh_bounds: Vec<Aabb> = self.meshes.iter().map(Mesh::bounds).collect();
        self.instances
            .iter()
            .map(|i| mesh_bounds[i.mesh].transformed(i.world_from_object))
            .fold(Aabb::EMPTY, Aabb::union)
    }

    /// Number of triangles drawn: each instance counts its mesh's triangles.
    pub fn triangle_count(&self) -> usize {
        self.instances.iter().map(|i| self.meshes[i.mesh].triangle_count()).sum()
    }

    /// Appends `other`'s meshes, materials, textures and instances, placing its
    /// instances with `world_from_other`. Its camera and lights are dropped.
    pub fn append(&mut self, other: Scene, world_from_other: Mat4) {
        let (meshes, materials, textures) = (self.meshes.len(), self.materials.len(), self.textures.len());
        self.meshes.extend(other.meshes);
        self.textures.extend(other.textures);
        self.materials.extend(other.materials.into_iter().map(|mut m| {
            m.base_color_texture = m.base_color_texture.map(|t| t + textures);
            m
        }));
        self.instances.extend(other.instances.into_iter().map(|mut i| {
            i.mesh += meshes;
            i.material += materials;
            i.world_from_object = world_from_other * i.world_from_object;
            i
        }));
    }

    /// Adds a light grey ground plane at the scene's lowest point, three times as wide
    /// as the scene, and lets the camera's far plane reach across it. Does nothing when
    /// the scene already has a ground.
    pub fn add_ground_plane(&mut self) {
        if self.has_ground {
            return;
        }
        self.has_ground = true;
        let b = self.bounds();
        let size = 3.0 * b.extent().x.max(b.extent().z).max(1e-3);
        self.meshes.push(crate::geometry::plane(size, size));
        self.materials.push(Material::new("ground", Vec3::splat(0.72)));
        self.instances.push(Instance {
            name: "ground".into(),
            mesh: self.meshes.len() - 1,
            material: self.materials.len() - 1,
            world_from_object: Mat4::from_translation(Vec3::new(b.center().x, b.min.y, b.center().z)),
            casts_shadow: true,
            motion: crate::Motion::Static,
        });
        let reach = self.camera.eye.distance(b.center()) + 2.0 * size;
        self.camera.far = self.camera.far.max(reach);
    }

    /// Checks every cross-reference and attribute so that later stages can index freely.
    pub fn validate(&self) -> Result<(), SceneError> {
        let scene = self.name.clone();
        for m in &self.meshes {
            let (p, n, t) = (m.positions.len(), m.normals.len(), m.uvs.len());
            if p != n || p != t {
                return Err(SceneError::AttributeCountMismatch {
                    scene,
                    mesh: m.name.clone(),
                    positions: p,
                    normals: n,
                    uvs: t,
                });
            }
            if !m.indices.len().is_multiple_of(3) || m.indices.iter().any(|&i| i as usize >= p) {
                let index = m.indices.iter().copied().find(|&i| i as usize >= p).unwrap_or(0);
                return Err(SceneError::BadIndices { scene, mesh: m.name.clone(), index, vertices: p });
            }
            if !m.positions.iter().chain(&m.normals).all(|v| v.is_finite()) {
                return Err(SceneError::NonFinite { scene, mesh: m.name.clone() });
            }
        }
        for m in &self.materials {
            if let Some(t) = m.base_color_texture
                && t >= self.textures.len()
            {
                let count = self.textures.len();
                return Err(SceneError::TextureOutOfRange {
                    scene,
                    material: m.name.clone(),
                    texture: t,
                    count,
                });
            }
        }
        for t in &self.textures {
            if t.rgba8.len() != 4 * (t.width as usize) * (t.height as usize) || t.width == 0 || t.height == 0
            {
                return Err(SceneError::BadTexture {
                    scene,
                    texture: t.name.clone(),
                    width: t.width,
                    height: t.height,
                    bytes: t.rgba8.len(),
                });
            }
        }
        for i in &self.instances {
            if i.mesh >= self.meshes.len() {
                return Err(SceneError::MeshOutOfRange {
                    scene,
                    instance: i.name.clone(),
                    mesh: i.mesh,
                    count: self.meshes.len(),
                });
            }
            if !i.world_from_object.is_finite() {
                return Err(SceneError::NonFiniteTransform { scene, instance: i.name.clone() });
            }
            if i.material >= self.materials.len() {
                return Err(SceneError::MaterialOutOfRange {
                    scene,
                    instance: i.name.clone(),
                    material: i.material,
                    count: self.materials.len(),
                });
            }
        }
        self.validate_lights_and_camera()
    }

    /// Checks the camera and every light against [`crate::limits`]: first the light
    /// each kind's `--light` draws, named by its kind, then the listed lights by
    /// name; and that no kind has two defaults.
    pub(crate) fn validate_lights_and_camera(&self) -> Result<(), SceneError> {
        let scene = &self.name;
        self.camera.validate().map_err(|problem| SceneError::BadCamera { scene: scene.clone(), problem })?;
        self.check_one_default_per_kind()?;
        let chosen = Light::KIND_NAMES.iter().filter_map(|&kind| Some((kind, self.light_of_kind(kind)?)));
        let listed = self.listed_lights().map(|l| (l.name.as_str(), &l.light));
        for (name, light) in chosen.chain(listed) {
            light.validate().map_err(|problem| SceneError::BadLight {
                scene: scene.clone(),
                light: name.into(),
                problem,
            })?;
        }
        Ok(())
    }
}
