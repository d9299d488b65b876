//! `gnomon bench --moving N`: instances that sway every frame, so that a bench times
//! what following moved casters costs (`Renderer::move_instances`: their transforms,
//! the culling trees and, once rays refine, the casters' BVH refitted, not rebuilt).

use std::time::Instant;

use glam::{Mat4, Vec3};
use gnomon_render::{GpuScene, Renderer};
use gnomon_scene::Scene;

/// The instances that move and where they started.
pub struct Mover {
    chosen: Vec<usize>,
    original: Vec<Mat4>,
    /// How far they sway: a hundredth of the scene's size.
    amplitude: f32,
}

impl Mover {
    /// `count` instances with geometry, spread evenly over the scene's list. Refuses
    /// a count of 0 or more than the scene has, naming `--moving` and what is valid.
    pub fn new(scene: &Scene, count: usize) -> anyhow::Result<Self> {
        let candidates: Vec<usize> = (0..scene.instances.len())
            .filter(|&i| !scene.meshes[scene.instances[i].mesh].indices.is_empty())
            .collect();
        anyhow::ensure!(
            (1..=candidates.len()).contains(&count),
            "--moving {count}: give 1 to {} (the instances of scene `{}` that have triangles)",
            candidates.len(),
            scene.name
        );
        let chosen: Vec<usize> = (0..count).map(|k| candidates[k * candidates.len() / count]).collect();
        let original = chosen.iter().map(|&i| scene.instances[i].world_from_object).collect();
        let amplitude = 0.01 * scene.bounds().extent().max_element();
        Ok(Self { chosen, original, amplitude })
    }

    /// Every instance with triangles but the one whose bounds are largest (a scene's
    /// ground, as a rule): the casters `compare --motion casters` sways. Refuses a
    /// scene with fewer than two such instances.
    pub fn all_but_the_largest(scene: &Scene) -> anyhow::Result<Self> {
        let candidates: Vec<usize> = (0..scene.instances.len())
            .filter(|&i| !scene.meshes[scene.instances[i].mesh].indices.is_empty())
            .collect();
        let size = |i: usize| {
            let inst = &scene.instances[i];
            scene.meshes[inst.mesh].bounds().transformed(inst.world_from_object).extent().length()
        };
        let largest = candidates.iter().copied().max_by(|&a, &b| size(a).total_cmp(&size(b)));
        let chosen: Vec<usize> = candidates.iter().copied().filter(|&i| Some(i) != largest).collect();
        anyhow::ensure!(
            !chosen.is_empty(),
            "--motion casters: scene `{}` has {} instance(s) with triangles; it needs a caster besides its largest",
            scene.name,
            candidates.len()
        );
        let original = chosen.iter().map(|&i| scene.instances[i].world_from_object).collect();
        let amplitude = 0.01 * scene.bounds().extent().max_element();
        Ok(Self { chosen, original, amplitude })
    }

    /// Marks the instances it moves as moving (`Motion::Dynamic`) in `scene`, before
    /// the scene is uploaded.
    pub fn declare_dynamic(&self, scene: &mut Scene) {
        for &i in &self.chosen {
            scene.instances[i].motion = gnomon_scene::Motion::Dynamic;
        }
    }

    /// For scale: the time to build the casters' BVH afresh and upload it (what a
    /// refit saves), in milliseconds.
    pub fn rebuild_ms(gpu: &gnomon_render::Gpu, scene: &Scene) -> anyhow::Result<f64> {
        let started = Instant::now();
        gnomon_render::rays::ShadowRays::new(gpu, scene)?;
        gpu.device.poll(gnomon_render::wgpu::PollType::wait_indefinitely())?;
        Ok(started.elapsed().as_secs_f64() * 1e3)
    }

    /// How many instances move.
    pub fn count(&self) -> usize {
        self.chosen.len()
    }

    /// Sways the chosen instances to where frame `frame` puts them and has the
    /// uploaded scene follow; returns the CPU time of following, in milliseconds.
    pub fn step(
        &self,
        renderer: &Renderer,
        uploaded: &mut GpuScene,
        scene: &mut Scene,
        frame: u32,
    ) -> anyhow::Result<f64> {
        let offset = Vec3::new(self.amplitude * (0.5 * frame as f32).sin(), 0.0, 0.0);
        for (&i, &start) in self.chosen.iter().zip(&self.original) {
            scene.instances[i].world_from_object = Mat4::from_translation(offset) * start;
        }
        let started = Instant::now();
        renderer.move_instances(uploaded, scene, &self.chosen)?;
        Ok(started.elapsed().as_secs_f64() * 1e3)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_count_out_of_range_names_the_flag_and_the_range() {
        let scene = gnomon_scene::builtin::spheres();
        let with_triangles = scene.instances.len();
        assert_eq!(Mover::new(&scene, with_triangles).unwrap().count(), with_triangles);
        for count in [0, with_triangles + 1] {
            let e = Mover::new(&scene, count).err().unwrap().to_string();
            assert!(e.contains(&format!("--moving {count}: give 1 to {with_triangles}")), "{e}");
        }
    }
}
