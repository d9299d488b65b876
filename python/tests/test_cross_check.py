"""Gnomon's tracers against an independent one: Embree (the `embreex` wheel) traces
the very segments the CPU reference traced, from the surfaces a frame drew, against
the same world-space triangles (`Reference.shadow_segments`,
`Reference.caster_triangles`), and its answers are set beside the reference's and the
GPU's `raytraced` frame's. Where they disagree, the cause is a tracer's own (its
triangle test, its rule at a shared edge), not an origin offset or a facing rule,
which all three share (docs/reference-and-metrics.md, "Cross-checked by Embree")."""

import os
import pathlib

import numpy as np
import pytest

import gnomon

embree_scene = pytest.importorskip("embreex.rtcore_scene")
embree_mesh = pytest.importorskip("embreex.mesh_construction")

SHARED = pathlib.Path(__file__).resolve().parents[3] / "shared" / "scenes"

# The bound (76): the tracers agree on all but 0.005 % of light-facing pixels.
MOST_DISAGREEING = 5e-5


def embree_occluded(triangles, segments):
    scene = embree_scene.EmbreeScene()
    embree_mesh.TriangleMesh(scene, triangles)
    hits = scene.run(
        segments["origin"], segments["direction"], dists=segments["length"].copy(), query="OCCLUDED"
    )
    return hits >= 0


def cross_check(renderer, scene, settings):
    """(light-facing pixels, reference ≠ Embree, raytraced ≠ Embree)."""
    truth = gnomon.reference(scene, settings, samples=1)
    frame = renderer.render(scene, settings.replace(technique="raytraced"))
    segments = truth.shadow_segments(frame)
    embree = embree_occluded(truth.caster_triangles(), segments)
    gpu_lit = frame.visibility.reshape(-1)[segments["pixel"]] >= 0.5
    pixels = len(segments["pixel"])
    assert pixels > 0.2 * settings.width * settings.height, "too few light-facing pixels to test"
    return pixels, int(np.sum(segments["occluded"] != embree)), int(np.sum(gpu_lit == embree))


def report(name, pixels, disagreeing, tracer):
    print(f"\n{name}: {pixels} rays; Embree against {tracer}: {disagreeing} ({100 * disagreeing / pixels:.4f} %)")
    assert disagreeing <= MOST_DISAGREEING * pixels, f"{tracer} and Embree disagree on {disagreeing} of {pixels} rays"


def test_embree_agrees_on_tessellated_spheres_under_a_grazing_sun(renderer):
    # Nine spheres of 2 304 triangles each and a box, the sun 4° up: the rays from
    # the spheres' lit sides graze their facets toward the terminator.
    settings = gnomon.Settings(width=160, height=90, sun_elevation=4, sun_azimuth=30)
    pixels, reference, raytraced = cross_check(renderer, gnomon.Scene.builtin("spheres"), settings)
    report("spheres, sun 4° up", pixels, reference, "the CPU reference")
    report("spheres, sun 4° up", pixels, raytraced, "raytraced")


SCANS = [("bunny/bunny.glb", 40), ("dragon/dragon_res3.glb", 40), ("dragon/dragon_res3.glb", 8)]
SCAN_IDS = ["bunny-40", "dragon-40", "dragon-8"]


def scan(renderer, model, sun_elevation):
    path = SHARED / model
    if not path.is_file():
        if os.environ.get("GNOMON_REQUIRE_SHARED"):
            pytest.fail(f"GNOMON_REQUIRE_SHARED is set and {path} is missing")
        pytest.skip(f"{path} is not here (../shared is not part of a clone)")
    settings = gnomon.Settings(width=320, height=180, sun_elevation=sun_elevation, sun_azimuth=30)
    return cross_check(renderer, gnomon.Scene.load(str(path)), settings)


@pytest.mark.parametrize("model, sun_elevation", SCANS, ids=SCAN_IDS)
def test_the_cpu_reference_agrees_with_embree_on_the_shared_scans(renderer, model, sun_elevation):
    pixels, reference, _ = scan(renderer, model, sun_elevation)
    report(f"{model}, sun {sun_elevation}° up", pixels, reference, "the CPU reference")


# Measured 2026-12-03 on lavapipe: the GPU's tracer disagrees with Embree (and with
# the CPU reference) on 1 ray of 14 323 on the dragon under a sun 40° up, 0.007 %;
# its cause is not found yet (issue 76). Strict: the test says so when it passes.
GPU_DISAGREES = pytest.mark.xfail(strict=True, reason="raytraced disagrees on 1 ray of 14 323 (issue 76, open)")


@pytest.mark.parametrize(
    "model, sun_elevation",
    [SCANS[0], pytest.param(*SCANS[1], marks=GPU_DISAGREES), SCANS[2]],
    ids=SCAN_IDS,
)
def test_raytraced_agrees_with_embree_on_the_shared_scans(renderer, model, sun_elevation):
    pixels, _, raytraced = scan(renderer, model, sun_elevation)
    report(f"{model}, sun {sun_elevation}° up", pixels, raytraced, "raytraced")
