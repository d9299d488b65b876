//! What the glTF 2.0 specification requires of a file's structure that the gltf crate
//! does not check, checked on the JSON before anything is built, each fault named
//! with its JSON path:
//!
//! - nodes form a forest (§3.5.3: no node has two parents, there are no cycles,
//!   reachable from a scene or not), no deeper than [`MAX_NODE_DEPTH`];
//! - a node's `rotation` is a unit quaternion (§3.5.2);
//! - `KHR_lights_punctual` lights have the ranges their extension gives: a spot's
//!   cones within (0, π/2], the inner below the outer, a positive range, and an
//!   intensity that is finite and not negative (and, since Gnomon maps it to its own
//!   radiance, within [`crate::limits::INTENSITY`]).

use gltf::json::Root;

/// The deepest node hierarchy Gnomon loads: 256 levels, far beyond any exporter's
/// (and a bound on the recursion that expands it).
pub const MAX_NODE_DEPTH: usize = 256;

/// Checks the node forest, the rotations and the lights of `json`.
pub fn check(json: &Root) -> Result<(), String> {
    node_forest(json)?;
    rotations(json)?;
    lights(json)
}

fn node_forest(json: &Root) -> Result<(), String> {
    let n = json.nodes.len();
    let mut parent: Vec<Option<usize>> = vec![None; n];
    for (p, node) in json.nodes.iter().enumerate() {
        for child in node.children.iter().flatten() {
            let c = child.value();
            if c >= n {
                return Err(format!("`nodes[{p}].children` names node {c}, of {n}"));
            }
            if let Some(first) = parent[c] {
                return Err(format!(
                    "node {c} has two parents, nodes {first} and {p}: glTF's nodes form a forest, each node \
                     a child of one parent at most (glTF 2.0, §3.5.3)"
                ));
            }
            parent[c] = Some(p);
        }
    }
    // Each node's depth (a root's is 0), following parents up to a node whose depth
    // is known or a root: a chain that comes back to a node on it is a cycle,
    // wherever it lies, reachable from a scene or not.
    let mut depth: Vec<Option<usize>> = vec![None; n];
    let mut on_chain = vec![false; n];
    for start in 0..n {
        let mut chain = Vec::new();
        let mut at = start;
        let known = loop {
            if let Some(d) = depth[at] {
                break Some(d);
            }
            if on_chain[at] {
                return Err(format!(
                    "nodes {} form a cycle in the node hierarchy: glTF's nodes form a forest (glTF 2.0, §3.5.3)",
                    cycle_words(&chain, at)
                ));
            }
            on_chain[at] = true;
            chain.push(at);
            match parent[at] {
                Some(p) => at = p,
                None => break None,
            }
        };
        // The chain's last node is a root, or the child of a node of known depth.
        for (d, &node) in (known.map_or(0, |k| k + 1)..).zip(chain.iter().rev()) {
            on_chain[node] = false;
            if d >= MAX_NODE_DEPTH {
                return Err(format!(
                    "the node hierarchy is deeper than {MAX_NODE_DEPTH} levels (node {node} is {} levels down)",
                    d + 1
                ));
            }
            depth[node] = Some(d);
        }
    }
    Ok(())
}

/// `3 → 5 → 3`: the cycle of `chain` that comes back to `at`.
fn cycle_words(chain: &[usize], at: usize) -> String {
    let from = chain.iter().position(|&n| n == at).unwrap_or(0);
    chain[from..].iter().chain([&at]).map(usize::to_string).collect::<Vec<_>>().join(" → ")
}

fn rotations(json: &Root) -> Result<(), String> {
    for (i, node) in json.nodes.iter().enumerate() {
        if let Some(q) = &node.rotation {
            let [x, y, z, w] = q.0;
            let length = (x * x + y * y + z * z + w * w).sqrt();
            // Exporters write unit quaternions to a few decimals.
            if !length.is_finite() || (length - 1.0).abs() > 1e-3 {
                return Err(format!(
                    "`nodes[{i}].rotation` = [{x}, {y}, {z}, {w}] is not a unit quaternion (its length is {length}); \
                     glTF asks for one (§3.5.2)"
                ));
            }
        }
    }
    Ok(())
}

fn lights(json: &Root) -> Result<(), String> {
    let Some(lights) = json.extensions.as_ref().and_then(|e| e.khr_lights_punctual.as_ref()) else {
        return Ok(());
    };
    for (i, light) in lights.lights.iter().enumerate() {
        let at = format!("`extensions.KHR_lights_punctual.lights[{i}]");
        let intensity = light.intensity;
        if !crate::limits::INTENSITY.allows(intensity) {
            return Err(format!(
                "{at}.intensity` = {intensity} is invalid: {} (KHR_lights_punctual: finite and not negative)",
                crate::limits::INTENSITY.valid
            ));
        }
        if let Some(range) = light.range
            && !(range.is_finite() && range > 0.0)
        {
            return Err(format!(
                "{at}.range` = {range} is invalid: a positive distance (KHR_lights_punctual)"
            ));
        }
        if let Some(spot) = &light.spot {
            let (inner, outer) = (spot.inner_cone_angle, spot.outer_cone_angle);
            let half_pi = std::f32::consts::FRAC_PI_2;
            if !(outer > 0.0 && outer <= half_pi) {
                return Err(format!(
                    "{at}.spot.outerConeAngle` = {outer} rad ({:.1}°) is invalid: in (0, π/2] (KHR_lights_punctual)",
                    outer.to_degrees()
                ));
            }
            if !(inner >= 0.0 && inner < outer) {
                return Err(format!(
                    "{at}.spot.innerConeAngle` = {inner} rad is invalid: in [0, outerConeAngle = {outer}) \
                     (KHR_lights_punctual)"
                ));
            }
        }
    }
    Ok(())
}
