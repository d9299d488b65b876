//! What the tests of the GPU tracers share: random rays through a scene, the same on
//! every run, and a cut-out card to test alpha against.

use glam::{Mat4, Vec3};
use gnomon_reference::TracedScene;
use gnomon_render::rays::{ShadowRay, ShadowRays};
use gnomon_scene::{AlphaMode, Instance, Material, Scene, Texture, Wrap, geometry};

/// A small xorshift generator: the same rays on every run.
pub struct Rng(pub u64);

impl Rng {
    pub fn next(&mut self) -> f32 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as f32 / (1u64 << 24) as f32
    }

    pub fn in_box(&mut self, min: Vec3, max: Vec3) -> Vec3 {
        min + (max - min) * Vec3::new(self.next(), self.next(), self.next())
    }

    pub fn direction(&mut self) -> Vec3 {
        loop {
            let v = self.in_box(Vec3::splat(-1.0), Vec3::ONE);
            if (0.01..=1.0).contains(&v.length_squared()) {
                return v.normalize();
            }
        }
    }
}

/// Random segments through the scene's bounds, of random lengths.
pub fn random_rays(scene: &Scene, count: usize, seed: u64) -> Vec<ShadowRay> {
    let bounds = scene.bounds();
    let mut rng = Rng(seed);
    let reach = bounds.extent().max_element();
    (0..count)
        .map(|_| ShadowRay {
            origin: rng.in_box(bounds.min, bounds.max),
            direction: rng.direction(),
            length: reach * (0.05 + rng.next()),
        })
        .collect()
}

/// A 16 × 16 alpha that varies smoothly across it, wrapped as `wrap` says, sampled
/// bilinearly (set `nearest` for nearest texels).
pub fn card_alpha(wrap: Wrap) -> Texture {
    let size = 16u32;
    let rgba8 = (0..size * size)
        .flat_map(|k| {
            let (i, j) = ((k % size) as f32, (k / size) as f32);
            let a = 127.5 + 127.5 * (0.9 * i).sin() * (0.7 * j + 0.3).cos();
            [255, 255, 255, a as u8]
        })
        .collect();
    Texture {
        name: "alpha".into(),
        width: size,
        height: size,
        rgba8,
        wrap_u: wrap,
        wrap_v: wrap,
        nearest: false,
    }
}

/// Adds to `scene` a square card `size` wide, double-sided, cut out where `alpha`
/// falls below 0.5, whose UVs run past the unit square (so the wrap modes matter),
/// placed by `world_from_object`.
pub fn add_cutout_card(scene: &mut Scene, alpha: Texture, size: f32, world_from_object: Mat4) {
    scene.textures.push(alpha);
    let mut card = Material::new("card", Vec3::ONE);
    card.base_color_texture = Some(scene.textures.len() - 1);
    card.alpha_mode = AlphaMode::Mask { cutoff: 0.5 };
    card.double_sided = true;
    scene.materials.push(card);
    let mut mesh = geometry::plane(size, size);
    for uv in &mut mesh.uvs {
        *uv = *uv * 2.5 - 0.7;
    }
    scene.meshes.push(mesh);
    scene.instances.push(Instance {
        name: "card".into(),
        mesh: scene.meshes.len() - 1,
        material: scene.materials.len() - 1,
        world_from_object,
        casts_shadow: true,
        motion: gnomon_scene::Motion::Static,
    });
}

/// How a tracer answered random rays against the CPU reference of a moved scene,
/// before and after it followed the move.
pub struct AfterMove {
    /// Rays answered differently before the move was followed.
    pub stale: usize,
    /// Rays answered differently after.
    pub moved: usize,
    /// Rays asked.
    pub rays: usize,
}

/// Moves every instance of `scene` (the built-in `spheres`) but the first, the ground:
/// turned, lifted, one far past the old bounds; then asks `tracer`, built on the scene
/// before the move, 20,000 random rays before and after `ShadowRays::move_instances`,
/// against the CPU reference built afresh on the moved scene.
pub fn move_every_sphere(scene: &mut Scene, tracer: &mut ShadowRays) -> AfterMove {
    let moved: Vec<usize> = (1..scene.instances.len()).collect();
    for (k, &i) in moved.iter().enumerate() {
        let lift = Mat4::from_translation(Vec3::new(0.4 * k as f32, 0.7, -0.3 * k as f32));
        scene.instances[i].world_from_object =
            lift * Mat4::from_rotation_y(0.5) * scene.instances[i].world_from_object;
    }
    scene.instances[moved[0]].world_from_object *= Mat4::from_translation(Vec3::new(12.0, 0.0, 0.0));
    let rays = random_rays(scene, 20_000, 0x2545_f491_4f6c_dd1d);
    let cpu = TracedScene::build(scene);
    let truth: Vec<bool> = rays.iter().map(|r| cpu.occluded(r.origin, r.direction, r.length)).collect();
    let differ = |answers: &[bool]| answers.iter().zip(&truth).filter(|(a, b)| a != b).count();
    let stale = differ(&tracer.occluded(&rays).unwrap());
    tracer.move_instances(scene, &moved).unwrap();
    AfterMove { stale, moved: differ(&tracer.occluded(&rays).unwrap()), rays: rays.len() }
}
