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
