"""The defaults under a light with a size, from Python as from the command line
(issue 74, docs/soft-shadows.md): with only the light's size given, the frame is
refined by penumbra beams over the light's area, and its penumbrae are within 0.01
of the ray-traced truth, where PCSS alone is several times further from it.

Small images (lavapipe renders on the CPU); the command line's own test of the same
claim is `refine_soft::the_defaults_beam_a_lights_penumbrae_to_the_truth`."""

import pytest

import gnomon

SIZE = dict(width=160, height=90)
# Issue 74's bound on a still view's penumbra MAE at the defaults.
DEFAULT_PENUMBRA_MAE = 0.01
# The reference's rays a pixel: its own noise in mid-penumbra is √(¼/1024) ≈ 0.016
# before stratification, and averages out over the penumbra's pixels.
REFERENCE_SAMPLES = 1024

LIGHTS = [
    ("contact", dict(light="spot", spot_radius=0.5)),
    ("grazing", dict(sun_angular_diameter=2)),
    ("spheres", dict(light="point", point_radius=0.3)),
]


@pytest.mark.parametrize("scene_name, light", LIGHTS, ids=["spot r 0.5", "sun 2°", "point r 0.3"])
def test_the_defaults_give_a_light_with_a_size_its_true_penumbra(renderer, scene_name, light):
    scene = gnomon.Scene.builtin(scene_name)
    settings = gnomon.Settings(**SIZE, **light)
    # The first frame of the scene's fresh upload beams, a quarter of the screen at
    # most; the still view then goes on from it (its last frame may beam nothing:
    # its unsure pixels may all hold their beams by then).
    [first] = renderer.render(scene, settings.replace(penumbra_frames=1)).lights
    assert first["traced_pixels"] and first["traced_pixels"] < SIZE["width"] * SIZE["height"] // 4, first
    frame = renderer.render(scene, settings)
    [report] = frame.lights
    assert report["refine"] == "rays", report
    assert report["rays_per_pixel"] > 1, report
    assert report["penumbra_frames"] and report["penumbra_frames"] > 1, "a still view gathers frames"

    truth = gnomon.reference(scene, settings, samples=REFERENCE_SAMPLES)
    ours = gnomon.compare(frame, truth)["penumbra"]
    alone = renderer.render(scene, gnomon.Settings(**SIZE, **light, technique="pcss", refine="off"))
    assert alone.lights[0]["refine"] == "off"
    pcss = gnomon.compare(alone, truth)["penumbra"]
    assert ours["pixels"] > 100, ours
    assert ours["mae"] <= DEFAULT_PENUMBRA_MAE, (ours, pcss)
    assert ours["mae"] <= 0.5 * pcss["mae"], (ours, pcss)
