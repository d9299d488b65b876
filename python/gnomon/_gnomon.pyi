# Type stubs for the extension module (python/src): what `import gnomon` offers.
from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

class SettingsError(ValueError):
    """A setting the command line would refuse too; the message is the command line's."""

class SceneError(ValueError):
    """A scene that cannot be built or loaded; the message names it."""

class GpuError(RuntimeError):
    """No GPU adapter, or the GPU refused the work."""

class Scene:
    """A scene: what is drawn and traced, the default camera and the lights."""
    @staticmethod
    def builtin(name: str) -> "Scene": ...
    @staticmethod
    def load(path: Union[str, PathLike[str]]) -> "Scene": ...
    @property
    def name(self) -> str: ...
    @property
    def camera(self) -> Dict[str, Any]: ...
    @property
    def lights(self) -> List[Dict[str, Any]]: ...
    @property
    def triangles(self) -> int: ...
    @property
    def warnings(self) -> List[str]: ...

_Value = Union[str, int, float, bool, Sequence[float], None]

class Settings:
    """The command line's settings: keywords are its flags, dashes as underscores."""
    def __init__(self, **flags: _Value) -> None: ...
    def replace(self, **flags: _Value) -> "Settings": ...
    def to_dict(self) -> Dict[str, Any]: ...
    @staticmethod
    def flags() -> List[Dict[str, Any]]: ...
    @property
    def technique(self) -> str: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...

class Frame:
    """A rendered frame; arrays are rows from the top."""
    color: npt.NDArray[np.uint8]
    visibility: npt.NDArray[np.float32]
    depth: npt.NDArray[np.float32]
    position: npt.NDArray[np.float32]
    normal: npt.NDArray[np.float32]
    object_id: npt.NDArray[np.uint32]
    times: Dict[str, Optional[float]]
    stats: Dict[str, int]
    technique: str
    width: int
    height: int

class Renderer:
    """A renderer on the GPU, kept across calls."""
    def __init__(self) -> None: ...
    def render(self, scene: Scene, settings: Settings) -> Frame: ...
    @property
    def adapter(self) -> Dict[str, str]: ...

class Reference:
    """The ray-traced reference for one view."""
    samples: int
    @property
    def visibility(self) -> npt.NDArray[np.float32]: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...

def reference(scene: Scene, settings: Settings, samples: Optional[int] = None) -> Reference: ...
def compare(frame: Frame, truth: Reference) -> Dict[str, Any]: ...
def builtin_scenes() -> List[str]: ...
def techniques() -> List[str]: ...
