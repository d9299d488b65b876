//! A validated glTF document, its buffers read and its images decoded, made into a
//! [`Scene`]: textures, materials and meshes (one per triangle primitive) first, then
//! the node forest walked from the scene's roots into instances, the first
//! perspective camera and the punctual lights, and last the defaults for what the
//! file lacks.

use std::path::Path;

use glam::{Mat4, Vec3};

use super::{FileExtras, images, lights, node_extras::node_motion, primitives, structure};
use crate::lights::KindType;
use crate::{
    AlphaMode, Camera, DirectionalLight, Instance, Material, Mesh, Motion, PointLight, Scene, SceneLight,
    SpotLight, Texture,
};

/// The scene `document` describes.
pub(super) fn build(
    path: &Path,
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    images: &[gltf::image::Data],
    budget: &mut super::sources::Budget,
) -> Result<(Scene, FileExtras), String> {
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
    let textures = textures(document, images, budget)?;
    let materials = materials(document, &textures.of_gltf_texture);
    let meshes = meshes(document, buffers, &materials)?;
    let mut placed = walk(document, &meshes, &materials.list)?;
    charge_placed(&meshes.list, &placed.instances, budget)?;
    drawn(&meshes, &mut placed)?;
    finish(Parts { name, textures: textures.list, materials: materials.list, meshes: meshes.list, placed })
}

/// The scene's textures and, for each glTF texture, its index among them: one per
/// distinct image and sampler, so that many glTF textures of one image hold its
/// pixels once (16 textures of one 4096² PNG took 3.2 GB when each had its copy).
struct Textures {
    list: Vec<Texture>,
    of_gltf_texture: Vec<usize>,
}

fn textures(
    document: &gltf::Document,
    images: &[gltf::image::Data],
    budget: &mut super::sources::Budget,
) -> Result<Textures, String> {
    let mut out = Textures { list: Vec::new(), of_gltf_texture: Vec::new() };
    let mut seen: Vec<(usize, Option<usize>)> = Vec::new();
    for t in document.textures() {
        let key = (t.source().index(), t.sampler().index());
        if let Some(at) = seen.iter().position(|k| *k == key) {
            out.of_gltf_texture.push(at);
            continue;
        }
        let image = images.get(key.0).ok_or_else(|| format!("texture {} has no image", t.index()))?;
        // Each distinct texture holds its own pixels, here and on the GPU.
        let texels = u64::from(image.width) * u64::from(image.height);
        let what = format!("texture {}, {}×{} texels,", t.index(), image.width, image.height);
        budget.take(texels.saturating_mul(crate::memory::BYTES_PER_TEXEL), &what)?;
        let sampler = t.sampler();
        out.list.push(Texture {
            name: t.name().unwrap_or("texture").to_string(),
            width: image.width,
            height: image.height,
            rgba8: images::to_rgba8(image).map_err(|e| format!("texture {}: {e}", t.index()))?,
            wrap_u: images::wrap(sampler.wrap_s()),
            wrap_v: images::wrap(sampler.wrap_t()),
            nearest: sampler.mag_filter() == Some(gltf::texture::MagFilter::Nearest),
        });
        seen.push(key);
        out.of_gltf_texture.push(out.list.len() - 1);
    }
    Ok(out)
}

/// The file's materials and a default one (last) for primitives without one, with
/// the texture-coordinate set each samples its base colour with.
struct Materials {
    list: Vec<Material>,
    texcoord_sets: Vec<u32>,
    default: usize,
}

fn materials(document: &gltf::Document, texture_of: &[usize]) -> Materials {
    let mut list = Vec::new();
    let mut texcoord_sets = Vec::new();
    for m in document.materials() {
        let pbr = m.pbr_metallic_roughness();
        let [r, g, b, a] = pbr.base_color_factor();
        let texture = pbr.base_color_texture();
        let mut material = Material::new(m.name().unwrap_or("material"), Vec3::new(r, g, b));
        material.alpha = a;
        material.base_color_texture =
            texture.as_ref().and_then(|t| texture_of.get(t.texture().index()).copied());
        material.alpha_mode = match m.alpha_mode() {
            gltf::material::AlphaMode::Opaque => AlphaMode::Opaque,
            gltf::material::AlphaMode::Mask => AlphaMode::Mask { cutoff: m.alpha_cutoff().unwrap_or(0.5) },
            gltf::material::AlphaMode::Blend => AlphaMode::Blend,
        };
        material.double_sided = m.double_sided();
        texcoord_sets.push(texture.map(|t| t.tex_coord()).unwrap_or(0));
        list.push(material);
    }
    let default = list.len();
    list.push(Material::new("default", Vec3::splat(0.8)));
    texcoord_sets.push(0);
    Materials { list, texcoord_sets, default }
}

/// One mesh per triangle primitive; for each glTF mesh, its primitives as (mesh,
/// material) indices; and the points and lines skipped.
struct Meshes {
    list: Vec<Mesh>,
    of_gltf_mesh: Vec<Vec<MeshMaterial>>,
    modes: primitives::ModeCounts,
}

/// A mesh of the scene and the material it is drawn with.
#[derive(Clone, Copy)]
struct MeshMaterial {
    mesh: usize,
    material: usize,
}

fn meshes(
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    materials: &Materials,
) -> Result<Meshes, String> {
    let mut out = Meshes { list: Vec::new(), of_gltf_mesh: Vec::new(), modes: Default::default() };
    for mesh in document.meshes() {
        let mut here = Vec::new();
        for (k, prim) in mesh.primitives().enumerate() {
            let label = format!("mesh {} (`{}`) primitive {k}", mesh.index(), mesh.name().unwrap_or(""));
            let material = prim.material().index().unwrap_or(materials.default);
            match primitives::read(&prim, buffers, materials.texcoord_sets[material], label)? {
                Some(mut m) => {
                    out.modes.triangles += 1;
                    out.modes.lying_bounds.extend(primitives::lying_bounds(&prim, &m.positions));
                    out.modes.degenerate_triangles += primitives::drop_degenerate(&mut m);
                    if !m.indices.is_empty() {
                        out.list.push(m);
                        here.push(MeshMaterial { mesh: out.list.len() - 1, material });
                    }
                }
                None if prim.mode() == gltf::mesh::Mode::Points => out.modes.points += 1,
                None => out.modes.lines += 1,
            }
        }
        out.of_gltf_mesh.push(here);
    }
    Ok(out)
}

/// What the node walk placed: instances, the first perspective camera, the lights
/// with the index of the file's light each is, and what to tell the user.
struct Placed {
    instances: Vec<Instance>,
    camera: Option<Camera>,
    lights: Vec<(usize, SceneLight)>,
    singular_nodes: usize,
    extras: FileExtras,
}

/// A node to visit: its parent's world transform, its depth and its parent's motion.
struct Visit<'a> {
    node: gltf::Node<'a>,
    parent: Mat4,
    depth: usize,
    parent_motion: Motion,
}

/// The nodes of the default scene (or of every root node), depth first.
fn walk(document: &gltf::Document, meshes: &Meshes, materials: &[Material]) -> Result<Placed, String> {
    let mut placed = Placed {
        instances: Vec::new(),
        camera: None,
        lights: Vec::new(),
        singular_nodes: 0,
        extras: Default::default(),
    };
    let mut stack: Vec<Visit> = roots(document)
        .into_iter()
        .map(|node| Visit { node, parent: Mat4::IDENTITY, depth: 0, parent_motion: Motion::Static })
        .collect();
    let mut visits = 0usize;
    while let Some(Visit { node, parent, depth, parent_motion }) = stack.pop() {
        visits += 1;
        // A node graph with a cycle would expand forever; `structure::check` refused
        // one already, and this bounds the walk whatever comes.
        if depth > structure::MAX_NODE_DEPTH || visits > 4 * document.nodes().len() + 16 {
            return Err(format!("node {} lies in a cycle or too deep in the node hierarchy", node.index()));
        }
        let local = Mat4::from_cols_array_2d(&node.transform().matrix());
        if !local.is_finite() {
            return Err(format!("node {} has a non-finite transform", node.index()));
        }
        let world = parent * local;
        // A node that moves carries its children along.
        let motion = parent_motion.max(node_motion(&node)?);
        if let Some(mesh) = node.mesh() {
            placed.singular_nodes += usize::from(world.determinant() == 0.0);
            for &MeshMaterial { mesh, material } in &meshes.of_gltf_mesh[mesh.index()] {
                placed.instances.push(Instance {
                    name: format!("node {} `{}`", node.index(), node.name().unwrap_or("")),
                    mesh,
                    material,
                    world_from_object: world,
                    casts_shadow: materials[material].alpha_mode != AlphaMode::Blend,
                    motion,
                });
            }
        }
        if placed.camera.is_none() {
            placed.camera = perspective_camera(&node, world);
        }
        if let Some(light) = node.light() {
            match lights::from_file(&light, world, &mut placed.extras.warnings) {
                Some(l) => {
                    let name = light.name().map_or_else(|| format!("light {}", light.index()), str::to_owned);
                    placed.lights.push((light.index(), SceneLight::listed(name, l)));
                }
                None => placed.extras.ignored_lights += 1,
            }
        }
        stack.extend(node.children().map(|node| Visit {
            node,
            parent: world,
            depth: depth + 1,
            parent_motion: motion,
        }));
    }
    Ok(placed)
}

/// The default scene's root nodes, or without scenes every node that is no child.
fn roots(document: &gltf::Document) -> Vec<gltf::Node<'_>> {
    match document.default_scene().or_else(|| document.scenes().next()) {
        Some(s) => s.nodes().collect(),
        None => {
            let mut is_child = vec![false; document.nodes().len()];
            for n in document.nodes() {
                for c in n.children() {
                    is_child[c.index()] = true;
                }
            }
            document.nodes().filter(|n| !is_child[n.index()]).collect()
        }
    }
}

/// The camera of `node`, placed at `world`, when it is a perspective one that looks
/// somewhere.
fn perspective_camera(node: &gltf::Node, world: Mat4) -> Option<Camera> {
    let camera = node.camera()?;
    let gltf::camera::Projection::Perspective(p) = camera.projection() else {
        return None;
    };
    let eye = world.transform_point3(Vec3::ZERO);
    let forward = world.transform_vector3(Vec3::NEG_Z).normalize_or_zero();
    let up = world.transform_vector3(Vec3::Y).normalize_or_zero();
    (forward != Vec3::ZERO).then(|| Camera {
        eye,
        target: eye + forward,
        up,
        fov_y_degrees: p.yfov().to_degrees(),
        near: p.znear(),
        // No `zfar`: an infinite projection (glTF 2.0, §3.10.3), which `finish` turns
        // into a far plane past everything the file holds.
        far: p.zfar().unwrap_or(f32::INFINITY),
    })
}

/// Warns of skipped points and lines and of singular transforms, and refuses a scene
/// that would draw nothing.
fn drawn(meshes: &Meshes, placed: &mut Placed) -> Result<(), String> {
    if let Some(skipped) = meshes.modes.skipped() {
        placed.extras.warnings.push(format!("{skipped} skipped: points and lines cast no shadow"));
    }
    if meshes.modes.degenerate_triangles > 0 {
        placed.extras.warnings.push(format!(
            "{} triangle(s) of zero area dropped: they cover no pixel and cast no shadow",
            meshes.modes.degenerate_triangles
        ));
    }
    let lying = &meshes.modes.lying_bounds;
    if !lying.is_empty() {
        // The first few by index: a hostile file may have millions.
        const NAMED: usize = 10;
        let mut list: Vec<String> = lying.iter().take(NAMED).map(usize::to_string).collect();
        if lying.len() > NAMED {
            list.push(format!("and {} more", lying.len() - NAMED));
        }
        placed.extras.warnings.push(format!(
            "the min/max of POSITION accessor(s) {} do not bound their data (glTF 2.0, §3.6.2.5): \
             Gnomon takes its bounds from the data, but other viewers may cull what lies outside",
            list.join(", ")
        ));
    }
    if placed.singular_nodes > 0 {
        placed.extras.warnings.push(format!(
            "{} node(s) with meshes have a singular transform (determinant 0): they flatten to nothing",
            placed.singular_nodes
        ));
    }
    if placed.instances.is_empty() && meshes.modes.degenerate_triangles > 0 {
        return Err(format!(
            "every triangle of its scene has zero area ({} dropped): nothing would be drawn",
            meshes.modes.degenerate_triangles
        ));
    }
    if placed.instances.is_empty() {
        return Err(match meshes.modes.skipped() {
            Some(skipped) => format!("has no triangles to draw in its scene, only {skipped}"),
            None => "has no triangle meshes in its scene".into(),
        });
    }
    if !draws_anything(&meshes.list, &placed.instances) {
        return Err(format!(
            "every triangle of its scene has zero area ({} instance(s) of {} mesh(es)): nothing would be drawn",
            placed.instances.len(),
            meshes.list.len()
        ));
    }
    Ok(())
}

/// Charges every instance's triangles as the casters' BVHs will hold them, placed in
/// world space: a mesh instanced a hundred times is held a hundred times there.
fn charge_placed(
    meshes: &[Mesh],
    instances: &[Instance],
    budget: &mut super::sources::Budget,
) -> Result<(), String> {
    use crate::memory::{BYTES_PER_INSTANCE, BYTES_PER_PLACED_TRIANGLE};
    let placed: u64 = instances.iter().map(|i| meshes[i.mesh].indices.len() as u64 / 3).sum();
    let bytes = placed
        .saturating_mul(BYTES_PER_PLACED_TRIANGLE)
        .saturating_add(instances.len() as u64 * BYTES_PER_INSTANCE);
    budget.take(bytes, &format!("its {} instances' {placed} placed triangles", instances.len()))
}

/// Whether any instance has a triangle of non-zero area once placed: a file of
/// degenerate triangles only (or of meshes flattened by their nodes) draws an empty
/// sky, which a calibration would then measure as "0 pixels".
fn draws_anything(meshes: &[Mesh], instances: &[Instance]) -> bool {
    instances.iter().any(|instance| {
        let mesh = &meshes[instance.mesh];
        // Placed a triangle at a time: usually the first answers, with no copy of the
        // mesh made per instance.
        let place = |i: u32| instance.world_from_object.transform_point3(mesh.positions[i as usize]);
        mesh.indices.chunks_exact(3).any(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(place);
            (b - a).cross(c - a).length_squared() > 0.0
        })
    })
}

/// A far plane for an infinite glTF projection: past the farthest corner of the
/// scene's bounds from the eye (with a margin for the depth test's rounding), so
/// that everything the file holds is drawn, and at least twice the near plane.
fn far_past_everything(camera: &Camera, bounds: &gnomon_math::Aabb) -> f32 {
    let farthest = bounds.corners().iter().map(|c| c.distance(camera.eye)).fold(0.0_f32, f32::max);
    (farthest * 1.05).max(camera.near * 2.0)
}

/// What the scene is made of.
struct Parts {
    name: String,
    textures: Vec<Texture>,
    materials: Vec<Material>,
    meshes: Vec<Mesh>,
    placed: Placed,
}

/// Whether the file lists a light of kind `K`.
fn lists<K: KindType>(listed: &[SceneLight]) -> bool {
    listed.iter().any(|l| K::of(&l.light).is_some())
}

/// The scene: the file's camera and lights, and where it has none, a camera fitted
/// to the bounds and Gnomon's default lights placed over them.
fn finish(parts: Parts) -> Result<(Scene, FileExtras), String> {
    let Parts { name, textures, materials, meshes, placed } = parts;
    let Placed { instances, camera, lights: mut found, mut extras, .. } = placed;
    // The light list in the file's order.
    found.sort_by_key(|(index, _)| *index);
    let listed: Vec<SceneLight> = found.into_iter().map(|(_, l)| l).collect();
    extras.has_sun = lists::<DirectionalLight>(&listed);
    extras.has_spot = lists::<SpotLight>(&listed);
    extras.has_point = lists::<PointLight>(&listed);
    let mut scene = Scene {
        name,
        meshes,
        materials,
        instances,
        camera: Camera {
            eye: Vec3::ONE,
            target: Vec3::ZERO,
            up: Vec3::Y,
            fov_y_degrees: 45.0,
            near: 0.1,
            far: 100.0,
        },
        lights: Vec::new(),
        ambient: Vec3::splat(0.12),
        textures,
        has_ground: false,
    };
    scene.validate().map_err(|e| e.to_string())?;
    let bounds = scene.bounds();
    let (center, radius) = (bounds.center(), bounds.bounding_radius().max(1e-3));
    extras.has_camera = camera.is_some();
    scene.camera = camera.unwrap_or_else(|| crate::framing::default_camera(&scene));
    if scene.camera.far == f32::INFINITY {
        scene.camera.far = far_past_everything(&scene.camera, &bounds);
    }
    scene.lights = listed;
    // A kind the file lists no light of gets Gnomon's default; one it lists draws its first.
    if !extras.has_sun {
        scene.set_default(lights::default_sun());
    }
    if !extras.has_spot {
        // Above and beside the centre, aimed at it.
        let above = center + Vec3::new(0.3, 1.6, 0.5) * radius;
        let direction = (center - above).normalize();
        scene.set_default(SpotLight {
            position: above,
            direction,
            range: 4.0 * radius,
            ..lights::default_spot()
        });
    }
    if !extras.has_point {
        // Above the centre, reaching past the bounds.
        let position = center + Vec3::new(0.2, 0.9, 0.3) * radius;
        scene.set_default(PointLight { position, range: 4.0 * radius, ..lights::default_point() });
    }
    // A light without a range reaches past everything the file holds.
    let reach = |position: Vec3| 4.0 * radius + position.distance(center);
    for l in &mut scene.lights {
        lights::give_range(&mut l.light, reach);
    }
    scene.validate_lights_and_camera().map_err(|e| e.to_string())?;
    Ok((scene, extras))
}
