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
) -> Result<(Scene, FileExtras), String> {
    let name = path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into());
    let textures = textures(document, images)?;
    let materials = materials(document);
    let meshes = meshes(document, buffers, &materials)?;
    let mut placed = walk(document, &meshes, &materials.list)?;
    drawn(&meshes, &mut placed)?;
    finish(Parts { name, textures, materials: materials.list, meshes: meshes.list, placed })
}

/// One texture per glTF texture, with its image and sampler.
fn textures(document: &gltf::Document, images: &[gltf::image::Data]) -> Result<Vec<Texture>, String> {
    document
        .textures()
        .map(|t| {
            let image = images
                .get(t.source().index())
                .ok_or_else(|| format!("texture {} has no image", t.index()))?;
            let sampler = t.sampler();
            Ok(Texture {
                name: t.name().unwrap_or("texture").to_string(),
                width: image.width,
                height: image.height,
                rgba8: images::to_rgba8(image).map_err(|e| format!("texture {}: {e}", t.index()))?,
                wrap_u: images::wrap(sampler.wrap_s()),
                wrap_v: images::wrap(sampler.wrap_t()),
                nearest: sampler.mag_filter() == Some(gltf::texture::MagFilter::Nearest),
            })
        })
        .collect()
}

/// The file's materials and a default one (last) for primitives without one, with
/// the texture-coordinate set each samples its base colour with.
struct Materials {
    list: Vec<Material>,
    texcoord_sets: Vec<u32>,
    default: usize,
}

fn materials(document: &gltf::Document) -> Materials {
    let mut list = Vec::new();
    let mut texcoord_sets = Vec::new();
    for m in document.materials() {
        let pbr = m.pbr_metallic_roughness();
        let [r, g, b, a] = pbr.base_color_factor();
        let texture = pbr.base_color_texture();
        let mut material = Material::new(m.name().unwrap_or("material"), Vec3::new(r, g, b));
        material.alpha = a;
        material.base_color_texture = texture.as_ref().map(|t| t.texture().index());
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
                Some(m) => {
                    out.modes.triangles += 1;
                    out.list.push(m);
                    here.push(MeshMaterial { mesh: out.list.len() - 1, material });
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
        far: p.zfar().unwrap_or(p.znear() * 1e5),
    })
}

/// Warns of skipped points and lines and of singular transforms, and refuses a scene
/// that would draw nothing.
fn drawn(meshes: &Meshes, placed: &mut Placed) -> Result<(), String> {
    if let Some(skipped) = meshes.modes.skipped() {
        placed.extras.warnings.push(format!("{skipped} skipped: points and lines cast no shadow"));
    }
    if placed.singular_nodes > 0 {
        placed.extras.warnings.push(format!(
            "{} node(s) with meshes have a singular transform (determinant 0): they flatten to nothing",
            placed.singular_nodes
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

/// Whether any instance has a triangle of non-zero area once placed: a file of
/// degenerate triangles only (or of meshes flattened by their nodes) draws an empty
/// sky, which a calibration would then measure as "0 pixels".
fn draws_anything(meshes: &[Mesh], instances: &[Instance]) -> bool {
    instances.iter().any(|instance| {
        let mesh = &meshes[instance.mesh];
        let world: Vec<Vec3> =
            mesh.positions.iter().map(|p| instance.world_from_object.transform_point3(*p)).collect();
        mesh.indices.chunks_exact(3).any(|t| {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| world[i as usize]);
            (b - a).cross(c - a).length_squared() > 0.0
        })
    })
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
