//! One memory budget for a frame, declared here: what each kind of data costs in
//! bytes as Gnomon holds it (on the CPU and, on a device without memory of its own
//! such as lavapipe, in the GPU's buffers too), the budget itself, and the charges
//! that name what a scene and a frame would take before anything is allocated.
//!
//! The loader charges a model's vertices, triangles and decoded images as it reads
//! them (`gltf_loader::sources::Budget`), every model of a scene file to one budget;
//! the renderer charges the whole frame (the scene, every light's maps, the image's
//! targets) before it allocates any of it. Refusals name the largest items.
//!
//! Each cost was measured as the peak resident memory of `gnomon render` on lavapipe
//! as one quantity grows with the rest fixed (`sh scripts/hostile-memory.sh` reports
//! the peaks of the hostile cases; docs/hardening-memory.md, "Round three"), then rounded up.

use crate::Scene;

/// The bytes a frame may take by default: with the ~190 MB the process itself holds
/// on lavapipe (wgpu, Mesa, compiled shaders), a frame at the budget peaks under
/// 1 GiB. Enough for Sponza at 1920×1080 (about 600 MB).
pub const DEFAULT_FRAME_BUDGET: u64 = 768 << 20;

/// The largest budget that may be asked for, in MiB ([`BUDGET_ENV`]): 1 TiB.
pub const MAX_BUDGET_MIB: u64 = 1 << 20;

/// The environment variable that sets the budget, in MiB: the user's to raise, never
/// a file's (a scene file that could raise its own budget would defeat it).
pub const BUDGET_ENV: &str = "GNOMON_MEMORY_MIB";

/// A vertex of a mesh: position, normal and UV on the CPU, their GPU buffers, and
/// the clusters' copies (measured: 35 k-vertex bunny, 2 M-vertex sparse files).
pub const BYTES_PER_VERTEX: u64 = 64;
/// A triangle of a mesh: its indices, meshlets and bounds, CPU and GPU.
pub const BYTES_PER_TRIANGLE: u64 = 128;
/// A triangle of a placed instance: the casters' BVHs hold every instance's
/// triangles in world space, for the GPU tracer and for the reference (measured:
/// `instances:50000`, 2 M placed triangles, 280 B each).
pub const BYTES_PER_PLACED_TRIANGLE: u64 = 320;
/// An instance: its transform, bounds, draw and culling records.
pub const BYTES_PER_INSTANCE: u64 = 1024;
/// A texel of a texture: RGBA8 on the CPU and on the GPU with its mip chain (4/3).
pub const BYTES_PER_TEXEL: u64 = 10;
/// A pixel of the image: every camera-sized target (depth, normals, positions,
/// lighting, masks, penumbra history) and their readbacks (measured: 227 B at the
/// defaults, 240 B with a sized sun's beams, 1000² to 2000²).
pub const BYTES_PER_PIXEL: u64 = 256;
/// A pixel of a ray-traced reference (`gnomon_reference::ReferenceImage`): its
/// per-pixel vectors (33 B) and, while the rows are gathered, each pixel's result
/// beside them (48 B); rounded up. A test there holds it above the layout.
pub const BYTES_PER_REFERENCE_PIXEL: u64 = 96;
/// A texel of a shadow map (32-bit depth; measured: 3.9 B from 2048² to 8192²).
pub const BYTES_PER_MAP_TEXEL: u64 = 4;
/// What a texel of a filterable map adds (four 32-bit moments, and the blur's copy).
pub const BYTES_PER_MOMENT_TEXEL: u64 = 32;
/// What a texel of a 2D map its rays refine adds: the touched layer of casters
/// thinner than a texel beside it (32-bit depth; `gnomon-render`'s `rays/touched.rs`).
pub const BYTES_PER_TOUCHED_TEXEL: u64 = 4;

/// One item of a frame's memory: what it is, and its bytes.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Charge {
    /// What it is, in words (`the image's targets, 1280×720`).
    pub what: String,
    /// Its bytes.
    pub bytes: u64,
}

/// A frame (or a load) that would take more memory than its budget.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error(
    "it would take about {} but may take at most {} ({}); its largest items: {}",
    size(*.total), size(*.budget), .source_of_budget, .largest
)]
pub struct OverBudget {
    /// The bytes asked for.
    pub total: u64,
    /// The budget.
    pub budget: u64,
    /// Where the budget came from (the default, the environment, the machine).
    pub source_of_budget: String,
    /// The largest items, in words.
    pub largest: String,
}

/// A budget: the bytes a frame may take, and where that limit came from, in words
/// (the default, the environment, the machine, a host).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FrameBudget {
    /// The bytes.
    pub bytes: u64,
    /// Where the limit came from (`the default; set GNOMON_MEMORY_MIB to raise it`).
    pub source: String,
}

/// The budget in force: [`BUDGET_ENV`] if set, else [`DEFAULT_FRAME_BUDGET`], and at
/// most the memory this machine has available.
pub fn frame_budget() -> Result<FrameBudget, String> {
    frame_budget_beside(None)
}

/// A window the user sized: its pixels are the user's choice, not a file's, so the
/// default budget grows by their targets ([`frame_budget_beside`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Window {
    /// The widest image the window can show (its largest monitor), in physical pixels.
    pub width: u32,
    /// The tallest image the window can show, in physical pixels.
    pub height: u32,
}

/// [`frame_budget`] for a front end that draws into `window` (the viewer): the
/// default then leaves [`DEFAULT_FRAME_BUDGET`] for the scene and its maps beside
/// the targets of a frame as large as the window, so that a window maximised on a
/// 4K monitor fits while a scene file's 8000×8000 image is still refused. A budget
/// the user set ([`BUDGET_ENV`]) is kept as it is; either is capped by the memory
/// this machine has available.
pub fn frame_budget_beside(window: Option<Window>) -> Result<FrameBudget, String> {
    let asked = asked_budget(std::env::var(BUDGET_ENV).ok().as_deref(), window)?;
    Ok(match available_memory() {
        Some(free) if free < asked.bytes => {
            FrameBudget { bytes: free, source: format!("what this machine has available; {}", asked.source) }
        }
        _ => asked,
    })
}

/// The budget asked for, before the machine's memory caps it: `env` (the value of
/// [`BUDGET_ENV`], if set) as it is, else the default with room for `window`.
fn asked_budget(env: Option<&str>, window: Option<Window>) -> Result<FrameBudget, String> {
    if let Some(text) = env {
        let mib = text.trim().parse::<u64>().ok().filter(|m| (1..=MAX_BUDGET_MIB).contains(m));
        let mib = mib.ok_or_else(|| {
            format!("{BUDGET_ENV} = `{text}` is invalid: a whole number of MiB, 1 to {MAX_BUDGET_MIB}")
        })?;
        return Ok(FrameBudget { bytes: mib << 20, source: format!("{BUDGET_ENV} = {mib}") });
    }
    Ok(match window {
        None => FrameBudget {
            bytes: DEFAULT_FRAME_BUDGET,
            source: format!("the default; set {BUDGET_ENV} to raise it"),
        },
        Some(Window { width, height }) => FrameBudget {
            bytes: DEFAULT_FRAME_BUDGET.saturating_add(pixels(width, height).saturating_mul(BYTES_PER_PIXEL)),
            source: format!(
                "the default, with room for a {width}×{height} window; set {BUDGET_ENV} to raise it"
            ),
        },
    })
}

/// `width × height`, widened before multiplying.
pub fn pixels(width: u32, height: u32) -> u64 {
    u64::from(width) * u64::from(height)
}

/// The memory this machine has available now (Linux: `MemAvailable`), or `None`
/// where it cannot tell.
fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib << 10)
}

/// Refuses `charges` if together they pass `budget`, naming the three largest.
pub fn refuse_over(charges: &[Charge], budget: &FrameBudget) -> Result<(), OverBudget> {
    let total = charges.iter().map(|c| c.bytes).fold(0u64, u64::saturating_add);
    if total <= budget.bytes {
        return Ok(());
    }
    let mut sorted: Vec<&Charge> = charges.iter().collect();
    sorted.sort_by_key(|c| std::cmp::Reverse(c.bytes));
    let largest =
        sorted.iter().take(3).map(|c| format!("{} {}", c.what, size(c.bytes))).collect::<Vec<_>>().join(", ");
    Err(OverBudget { total, budget: budget.bytes, source_of_budget: budget.source.clone(), largest })
}

/// What `scene` takes as Gnomon holds it: its meshes, its instances and their
/// placed triangles, and its textures.
pub fn scene_charges(scene: &Scene) -> Vec<Charge> {
    let vertices: u64 = scene.meshes.iter().map(|m| m.positions.len() as u64).sum();
    let triangles: u64 = scene.meshes.iter().map(|m| m.indices.len() as u64 / 3).sum();
    let placed: u64 = scene
        .instances
        .iter()
        .map(|i| scene.meshes.get(i.mesh).map_or(0, |m| m.indices.len() as u64 / 3))
        .sum();
    let texels: u64 = scene.textures.iter().map(|t| u64::from(t.width) * u64::from(t.height)).sum();
    let n = scene.instances.len() as u64;
    vec![
        Charge {
            what: format!("{} meshes' {vertices} vertices and {triangles} triangles", scene.meshes.len()),
            bytes: vertices
                .saturating_mul(BYTES_PER_VERTEX)
                .saturating_add(triangles.saturating_mul(BYTES_PER_TRIANGLE)),
        },
        Charge {
            what: format!("{n} instances' {placed} placed triangles"),
            bytes: placed.saturating_mul(BYTES_PER_PLACED_TRIANGLE).saturating_add(n * BYTES_PER_INSTANCE),
        },
        Charge {
            what: format!("{} textures' {texels} texels", scene.textures.len()),
            bytes: texels.saturating_mul(BYTES_PER_TEXEL),
        },
    ]
}

/// `bytes` in words: `8.0 GiB`, `294.0 KiB`.
pub fn size(bytes: u64) -> String {
    match bytes {
        b if b >= 1 << 30 => format!("{:.1} GiB", b as f64 / f64::from(1u32 << 30)),
        b if b >= 1 << 20 => format!("{:.1} MiB", b as f64 / f64::from(1u32 << 20)),
        b if b >= 1 << 10 => format!("{:.1} KiB", b as f64 / 1024.0),
        b => format!("{b} bytes"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn budget(bytes: u64) -> FrameBudget {
        FrameBudget { bytes, source: "x".into() }
    }

    #[test]
    fn a_refusal_names_the_largest_items_and_the_budget() {
        let charges = [
            Charge { what: "a".into(), bytes: 10 << 20 },
            Charge { what: "b".into(), bytes: 900 << 20 },
            Charge { what: "c".into(), bytes: 1 << 20 },
            Charge { what: "d".into(), bytes: 5 << 20 },
        ];
        assert!(refuse_over(&charges, &budget(1 << 30)).is_ok());
        let e = refuse_over(&charges, &budget(768 << 20)).unwrap_err().to_string();
        assert!(e.contains("b 900.0 MiB, a 10.0 MiB, d 5.0 MiB") && e.contains("at most 768.0 MiB"), "{e}");
        assert!(!e.contains("c 1.0"), "only the three largest: {e}");
    }

    #[test]
    fn a_window_makes_room_for_its_own_targets_and_no_more() {
        let plain = asked_budget(None, None).unwrap();
        assert_eq!(plain.bytes, DEFAULT_FRAME_BUDGET);
        let uhd = asked_budget(None, Some(Window { width: 3840, height: 2160 })).unwrap();
        let targets = 3840 * 2160 * BYTES_PER_PIXEL;
        assert_eq!(uhd.bytes, DEFAULT_FRAME_BUDGET + targets);
        assert!(uhd.source.contains("3840×2160"), "{}", uhd.source);
        // A frame as large as the window fits beside a default scene; one a pixel
        // taller does not, and the default alone refuses it.
        let frame = |height: u64| Charge { what: "targets".into(), bytes: 3840 * height * BYTES_PER_PIXEL };
        let scene = Charge { what: "scene".into(), bytes: DEFAULT_FRAME_BUDGET };
        assert!(refuse_over(&[frame(2160), scene.clone()], &uhd).is_ok());
        assert!(refuse_over(&[frame(2161), scene], &uhd).is_err());
        assert!(refuse_over(&[frame(2160)], &plain).is_err());
        // The user's budget is kept as it is, window or not; a bad one is refused.
        let set = asked_budget(Some("100"), Some(Window { width: 3840, height: 2160 })).unwrap();
        assert_eq!((set.bytes, set.source.as_str()), (100 << 20, "GNOMON_MEMORY_MIB = 100"));
        for bad in ["0", "lots", "-5", "1048577"] {
            assert!(asked_budget(Some(bad), None).unwrap_err().contains("1 to 1048576"), "{bad}");
        }
        // No overflow for the largest window that can be named.
        let huge = asked_budget(None, Some(Window { width: u32::MAX, height: u32::MAX })).unwrap();
        assert_eq!(huge.bytes, u64::MAX);
    }

    #[test]
    fn instancing_a_mesh_charges_every_placed_copy() {
        let mut scene = crate::builtin::build("spheres").unwrap();
        let once: u64 = scene_charges(&scene).iter().map(|c| c.bytes).sum();
        let copies = scene.instances.clone();
        for _ in 0..9 {
            scene.instances.extend(copies.iter().cloned());
        }
        let ten: u64 = scene_charges(&scene).iter().map(|c| c.bytes).sum();
        assert!(ten > 5 * once, "ten copies of every instance: {once} then {ten}");
    }
}
