from os import PathLike
from typing import Any, Literal, Mapping, Sequence, Union

import numpy as np
import numpy.typing as npt

Signal = Union[float, Sequence[tuple[float, float]], str]

__version__: str

class ModelError(ValueError): ...
class DataError(ValueError): ...

def finger_angles(
    g: Union[float, npt.ArrayLike],
    gob1: float | None = ...,
    gob2: float | None = ...,
    gob3: float | None = ...,
    model: str | None = ...,
    out: npt.NDArray[np.float64] | None = ...,
) -> npt.NDArray[np.float64]: ...

class Model:
    def __init__(
        self, path: Union[str, PathLike[str]], config: Union[str, PathLike[str], None] = ...
    ) -> None: ...
    @property
    def path(self) -> str: ...
    @property
    def name(self) -> str: ...
    def info(self) -> dict[str, Any]: ...
    def dot(self, product: bool = ...) -> str: ...
    def simulate(
        self,
        until: float | None = ...,
        inputs: Mapping[str, Signal] | None = ...,
        sample: float | None = ...,
        parameters: Mapping[str, float] | None = ...,
        init: Mapping[str, float] | None = ...,
    ) -> dict[str, Any]: ...
    def check(
        self,
        properties: Sequence[str] | None = ...,
        method: str = ...,
        budget: float = ...,
        depth: int = ...,
    ) -> dict[str, Any]: ...
    def reach_set(
        self,
        properties: Sequence[str] | None = ...,
        budget: float = ...,
        order: int = ...,
        step: float = ...,
    ) -> dict[str, Any]: ...
    def reach_vertices(self, x: str, y: str, **kwargs: Any) -> npt.NDArray[np.float64]: ...

def load(
    path: Union[str, PathLike[str]], config: Union[str, PathLike[str], None] = ...
) -> Model: ...
def hand(
    objects: Sequence[str] = ...,
    mode: str = ...,
    spread: float | None = ...,
    g: float = ...,
    g_a: float | None = ...,
    g_b: float | None = ...,
    g_c: float | None = ...,
) -> dict[str, Any]: ...
def joint_state(
    objects: Sequence[str] = ...,
    mode: str = ...,
    spread: float | None = ...,
    g: float = ...,
    g_a: float | None = ...,
    g_b: float | None = ...,
    g_c: float | None = ...,
) -> dict[str, Any]: ...
def finger(
    g: float = ...,
    objects: Sequence[str] = ...,
    gob1: float | None = ...,
    gob2: float | None = ...,
    gob3: float | None = ...,
) -> dict[str, Any]: ...
def hand_sweep(
    objects: Sequence[str],
    offsets: npt.ArrayLike,
    mode: str = ...,
    spread: float | None = ...,
    g: float = ...,
    g_a: float | None = ...,
    g_b: float | None = ...,
    g_c: float | None = ...,
    threads: int = ...,
) -> dict[str, Any]: ...
def finger_sweep(
    objects: Sequence[str], offsets: npt.ArrayLike, g: float = ..., threads: int = ...
) -> dict[str, Any]: ...
def diagnose(
    *files: Union[str, PathLike[str]],
    model: Union[str, PathLike[str], None] = ...,
    significance: float = ...,
    threads: int = ...,
    noise: dict[str, float] | None = ...,
) -> dict[str, Any]: ...
def set_log_level(level: Literal["debug", "info", "warning"] | None) -> None: ...
