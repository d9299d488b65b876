"""`import gnomon` against the command line, its errors, and its resources.

Each test renders the smallest image that still tests its claim (lavapipe renders
on the CPU)."""

import _thread
import signal
import subprocess
import threading
import time

import numpy as np
import pytest
from PIL import Image

import gnomon

SIZE = dict(width=96, height=54)


def run_cli(cli, *args):
    done = subprocess.run([cli, *args], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


@pytest.mark.parametrize(
    "flags",
    [
        dict(technique="pcf2x2"),
        dict(technique="pcss", sun_angular_diameter=3),
        dict(technique="evsm4", light="spot"),
    ],
    ids=["pcf2x2", "pcss", "evsm4-spot"],
)
def test_arrays_equal_the_command_lines_bit_for_bit(renderer, cli, tmp_path, flags):
    settings = gnomon.Settings(**SIZE, **flags)
    frame = renderer.render(gnomon.Scene.builtin("spheres"), settings)
    argv = ["render", "spheres", "-o", str(tmp_path / "color.png"), "--aov-out", str(tmp_path), "--aov-format", "npy"]
    for name, value in {**SIZE, **flags}.items():
        argv += [f"--{name.replace('_', '-')}", str(value)]
    run_cli(cli, *argv)
    color = np.asarray(Image.open(tmp_path / "color.png").convert("RGBA"))
    assert frame.color.shape == (54, 96, 4) and frame.color.dtype == np.uint8
    assert np.array_equal(frame.color, color)
    for name in ["visibility", "depth", "position", "normal"]:
        ours = getattr(frame, name)
        theirs = np.load(tmp_path / f"{name}.npy")
        assert ours.dtype == np.float32 and ours.shape == theirs.shape, name
        # Bit for bit, NaNs included.
        assert np.array_equal(ours.view(np.uint32), theirs.view(np.uint32)), name
    ids = np.load(tmp_path / "object_id.npy")
    assert np.array_equal(frame.object_id.astype(np.float32), ids)


def test_compare_gives_the_command_lines_metrics(renderer, cli, tmp_path):
    flags = dict(technique="hard", refine="off", shadow_res=256, **SIZE)
    settings = gnomon.Settings(**flags)
    scene = gnomon.Scene.builtin("spheres")
    frame = renderer.render(scene, settings)
    measured = gnomon.compare(frame, gnomon.reference(scene, settings))
    argv = ["compare", "spheres", "--techniques", "hard", "--no-cache", "--timing-frames", "1", "-o", str(tmp_path)]
    for name, value in flags.items():
        if name != "technique":
            argv += [f"--{name.replace('_', '-')}", str(value)]
    run_cli(cli, *argv)
    import json

    row = json.loads((tmp_path / "metrics.json").read_text())["rows"][0]
    for key in ["mismatch_rate", "false_shadow_rate", "false_lit_rate", "mae"]:
        assert measured[key] == row[key], key
    assert measured["drawn"] == row["drawn"]
    # A coarse map with no rays is wrong somewhere; inverted, it is wrong almost everywhere.
    assert measured["drawn"]["mismatch_rate"] > 0
    frame.visibility[...] = 1.0 - frame.visibility
    inverted = gnomon.compare(frame, gnomon.reference(scene, settings))
    assert inverted["drawn"]["mismatch_rate"] > 0.9


def test_bad_settings_raise_the_command_lines_errors():
    with pytest.raises(gnomon.SettingsError, match=r"--technique = nope is invalid"):
        gnomon.Settings(technique="nope")
    with pytest.raises(ValueError, match=r"--shadow-res = 3 is invalid: 256 to 8192"):
        gnomon.Settings(shadow_res=3)
    with pytest.raises(gnomon.SettingsError, match=r"unknown setting `no-such-flag`"):
        gnomon.Settings(no_such_flag=1)
    with pytest.raises(gnomon.SettingsError, match=r"camera_eye: a sequence must hold numbers"):
        gnomon.Settings(camera_eye=("a", 2, 3))
    with pytest.raises(gnomon.SettingsError, match=r"samples = 0 is invalid"):
        gnomon.reference(gnomon.Scene.builtin("spheres"), gnomon.Settings(**SIZE), samples=0)


def test_settings_are_the_command_lines():
    settings = gnomon.Settings(technique="pcss", shadow_res=1024, camera_eye=(0, 2, 5), ground=True)
    assert settings.technique == "pcss"
    table = settings.to_dict()
    assert table["camera"]["eye"] == [0.0, 2.0, 5.0]
    assert table["scene"]["ground"] is True
    assert settings.replace(technique="hard").technique == "hard"
    names = {f["name"]: f for f in gnomon.Settings.flags()}
    assert names["shadow_res"]["flag"] == "--shadow-res"
    assert "pcss" in gnomon.techniques()


def test_bad_scenes_and_files_raise_scene_errors(tmp_path):
    with pytest.raises(gnomon.SceneError, match=r"unknown scene `nowhere`: give one of the built-in scenes"):
        gnomon.Scene.builtin("nowhere")
    broken = tmp_path / "broken.glb"
    broken.write_bytes(b"glTF" + bytes([2, 0, 0, 0, 64, 0, 0, 0]) + b"z" * 52)
    with pytest.raises(gnomon.SceneError, match=r"broken\.glb: is a binary glTF \(GLB\) with a chunk of \d+ bytes that runs past the file's end"):
        gnomon.Scene.load(broken)
    with pytest.raises(gnomon.SceneError, match=r"missing\.glb"):
        gnomon.Scene.load(tmp_path / "missing.glb")


def test_a_reference_of_another_view_is_refused(renderer):
    scene = gnomon.Scene.builtin("spheres")
    frame = renderer.render(scene, gnomon.Settings(**SIZE))
    with pytest.raises(ValueError, match=r"the frame is 96×54 and the reference 48×27"):
        gnomon.compare(frame, gnomon.reference(scene, gnomon.Settings(width=48, height=27)))
    with pytest.raises(ValueError, match=r"different views or lights"):
        gnomon.compare(frame, gnomon.reference(scene, gnomon.Settings(sun_elevation=20, **SIZE)))


def test_a_frame_or_reference_over_the_memory_budget_is_refused_up_front(monkeypatch):
    # The default budget (768 MiB): a renderer reads it when it is made.
    monkeypatch.delenv("GNOMON_MEMORY_MIB", raising=False)
    renderer = gnomon.Renderer()
    scene = gnomon.Scene.builtin("spheres")
    # 4000²: 3.8 GiB of targets and 1.4 GiB of reference, each refused before it is
    # allocated; its largest target (244 MiB) fits any device's largest buffer.
    huge = gnomon.Settings(width=4000, height=4000)
    with pytest.raises(MemoryError, match=r"the image's targets, 4000×4000 .* GiB"):
        renderer.render(scene, huge)
    with pytest.raises(MemoryError, match=r"the reference's pixels, 4000×4000"):
        gnomon.reference(scene, huge)
    renderer.render(scene, gnomon.Settings(**SIZE))  # and the renderer still renders
    monkeypatch.setenv("GNOMON_MEMORY_MIB", "lots")
    with pytest.raises(gnomon.SettingsError, match=r"GNOMON_MEMORY_MIB = `lots` is invalid"):
        gnomon.reference(scene, gnomon.Settings(**SIZE))


def resident_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def test_a_renderer_reused_for_100_frames_does_not_grow(renderer):
    scene = gnomon.Scene.builtin("spheres")
    settings = gnomon.Settings(width=128, height=128)
    for _ in range(20):
        renderer.render(scene, settings)
    before = resident_bytes()
    for _ in range(80):
        frame = renderer.render(scene, settings)
        del frame
    grown = resident_bytes() - before
    # A frame's arrays are 0.6 MB: keeping each would grow 50 MB over 80 frames.
    assert grown < 16 * 2**20, f"grew {grown / 2**20:.1f} MiB over 80 frames"


def test_tracing_releases_the_gil():
    scene = gnomon.Scene.builtin("spheres")
    settings = gnomon.Settings(width=320, height=180, sun_angular_diameter=2)
    ticks = 0
    finished = threading.Event()

    def trace():
        gnomon.reference(scene, settings, samples=64)
        finished.set()

    worker = threading.Thread(target=trace)
    worker.start()
    while not finished.is_set():
        ticks += 1
        time.sleep(0.001)
    worker.join()
    assert ticks > 20, f"the main thread ran only {ticks} times while the reference was traced"


def test_ctrl_c_interrupts_a_long_trace():
    scene = gnomon.Scene.builtin("spheres")
    settings = gnomon.Settings(width=1280, height=720, sun_angular_diameter=2)
    # Python's own Ctrl-C handler, as an interactive session has it: a process
    # started in the background by a non-interactive shell ignores SIGINT, and
    # interrupt_main then does nothing (so the test would fail there, whatever the
    # trace does).
    previous = signal.signal(signal.SIGINT, signal.default_int_handler)
    try:
        threading.Timer(0.5, _thread.interrupt_main).start()
        started = time.monotonic()
        with pytest.raises(KeyboardInterrupt):
            gnomon.reference(scene, settings, samples=256)
        assert time.monotonic() - started < 5.0
    finally:
        signal.signal(signal.SIGINT, previous)
