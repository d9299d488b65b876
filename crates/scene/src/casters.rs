//! Which of a scene's meshes are closed, for `cull auto`: a shadow pass may cull one
//! face of a caster only when its mesh is closed ([`gnomon_math::topology`]).

use gnomon_math::topology::{self, Closedness};

use crate::{Mesh, Scene};

impl Mesh {
    /// Whether the mesh is closed once coincident positions are welded
    /// ([`gnomon_math::topology`]): only then may the shadow pass cull one of its faces.
    pub fn closedness(&self) -> Closedness {
        let triangles: Vec<[u32; 3]> = self.indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
        topology::closedness(&self.positions, &triangles, topology::weld_tolerance(&self.positions))
    }

    /// The volume a closed mesh encloses, signed by its winding: positive where its
    /// triangles wind counter-clockwise seen from outside (their right-hand normals
    /// point out), negative where they wind the other way; the divergence theorem's
    /// Σ v0 · (v1 × v2) / 6 over its triangles. Of an open mesh it measures nothing.
    pub fn signed_volume(&self) -> f64 {
        let at = |i: u32| self.positions[i as usize].as_dvec3();
        let sum: f64 = self.indices.chunks_exact(3).map(|t| at(t[0]).dot(at(t[1]).cross(at(t[2])))).sum();
        sum / 6.0
    }
}

/// How many of a scene's shadow-casting meshes are open, as `cull auto` sees them.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpenCasters {
    /// Meshes of single-sided casters (double-sided ones draw both faces anyway).
    pub meshes: usize,
    /// Of those, the open ones: their casters draw both faces under `cull auto`.
    pub open_meshes: usize,
    /// Triangles drawn by single-sided casters, counting each instance.
    pub triangles: usize,
    /// Of those, the triangles of open meshes.
    pub open_triangles: usize,
}

impl Scene {
    /// For each mesh, whether it is closed ([`Mesh::closedness`]).
    pub fn closed_meshes(&self) -> Vec<bool> {
        self.meshes.iter().map(|m| m.closedness().is_closed()).collect()
    }

    /// How many single-sided casters are open, given [`Scene::closed_meshes`].
    pub fn open_casters(&self, closed: &[bool]) -> OpenCasters {
        let mut count = OpenCasters::default();
        let mut seen = vec![false; self.meshes.len()];
        for inst in &self.instances {
            if !inst.casts_shadow || self.materials[inst.material].double_sided {
                continue;
            }
            let open = !closed[inst.mesh];
            let triangles = self.meshes[inst.mesh].triangle_count();
            count.triangles += triangles;
            count.open_triangles += if open { triangles } else { 0 };
            if !std::mem::replace(&mut seen[inst.mesh], true) {
                count.meshes += 1;
                count.open_meshes += usize::from(open);
            }
        }
        count
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use crate::geometry;

    #[test]
    fn a_closed_meshs_signed_volume_is_its_volume_and_its_winding() {
        let cuboid = geometry::cuboid(Vec3::new(1.0, 2.0, 3.0));
        assert!((cuboid.signed_volume() - 48.0).abs() < 1e-9, "{}", cuboid.signed_volume());
        let sphere = geometry::uv_sphere(1.0, 48, 24);
        let ball = 4.0 / 3.0 * std::f64::consts::PI;
        assert!(
            sphere.signed_volume() > 0.97 * ball && sphere.signed_volume() < ball,
            "{}",
            sphere.signed_volume()
        );
        // Wound the other way round, every triangle: the same volume, negative.
        let mut inside_out = cuboid.clone();
        inside_out.indices.chunks_exact_mut(3).for_each(|t| t.swap(1, 2));
        assert!((inside_out.signed_volume() + 48.0).abs() < 1e-9);
        // Moved, it encloses the same volume.
        let mut moved = cuboid;
        moved.positions.iter_mut().for_each(|p| *p += Vec3::new(10.0, -4.0, 7.0));
        assert!((moved.signed_volume() - 48.0).abs() < 1e-6);
    }
}
