"""Gnomon from Python: shadow maps rendered on the GPU and measured against
ray-traced truth, with numpy arrays in and out.

    import gnomon
    scene = gnomon.Scene.builtin("spheres")
    settings = gnomon.Settings(technique="pcss", width=320, height=180)
    frame = gnomon.Renderer().render(scene, settings)
    truth = gnomon.reference(scene, settings)
    print(gnomon.compare(frame, truth)["drawn"]["mismatch_rate"])

The settings are the command line's (`gnomon render --help`), named as its flags
with underscores; their checks and error text are the command line's too.
"""

from ._gnomon import (
    Frame,
    GpuError,
    Reference,
    Renderer,
    Scene,
    SceneError,
    Settings,
    SettingsError,
    builtin_scenes,
    compare,
    reference,
    techniques,
)

__all__ = [
    "Frame",
    "GpuError",
    "Reference",
    "Renderer",
    "Scene",
    "SceneError",
    "Settings",
    "SettingsError",
    "builtin_scenes",
    "compare",
    "reference",
    "techniques",
]
