//! What Gnomon reads from a glTF node's `extras`: whether it moves. A node written
//! `"extras": {"motion": "dynamic"}` is expected to move, with everything under it;
//! any other extras are left to other tools.

use crate::Motion;

/// The part of a node's extras Gnomon reads; every other field is ignored.
#[derive(serde::Deserialize)]
struct NodeExtras {
    #[serde(default)]
    motion: Motion,
}

/// The motion a node's extras give it: static where they say nothing. An error names
/// the node and the value where `motion` is neither "static" nor "dynamic".
pub(super) fn node_motion(node: &gltf::Node) -> Result<Motion, String> {
    let Some(raw) = node.extras() else { return Ok(Motion::Static) };
    match serde_json::from_str::<NodeExtras>(raw.get()) {
        Ok(extras) => Ok(extras.motion),
        // Extras that are not an object (a string, a number) are another tool's.
        Err(_) if !raw.get().trim_start().starts_with('{') => Ok(Motion::Static),
        Err(e) => Err(format!(
            "node {} has extras whose `motion` is not \"static\" or \"dynamic\": {e}",
            node.index()
        )),
    }
}
