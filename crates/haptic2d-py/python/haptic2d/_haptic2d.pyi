# Stubs of the compiled module haptic2d._haptic2d (src/*.rs). Private: use the haptic2d package.
import os
from typing import Any, Dict, List, Optional, Tuple, Union, final

import numpy as np

__all__ = [
    "SceneError",
    "World",
    "HapticSystem",
    "wall_run",
    "peg_run",
    "model_names",
    "law_params",
    "sweep_task",
    "sweep_models",
    "reproduce",
    "study_present",
    "devices",
    "__version__",
]

__version__: str

class SceneError(ValueError):
    field: Optional[str]
    fix: Optional[str]
    source: str
    errors: List[Tuple[str, str, str]]

@final
class World:
    name: str
    description: str
    source: str
    warnings: List[str]
    @staticmethod
    def load(name_or_path: str, rate: Optional[float] = None) -> World: ...
    @staticmethod
    def from_toml(text: str, source: str = "<string>", rate: Optional[float] = None) -> World: ...
    def copy(self) -> World: ...
    def step(self, n: int = 1) -> None: ...
    def run(self, duration: float, every: int = 1) -> Dict[str, np.ndarray]: ...
    @property
    def time(self) -> float: ...
    @property
    def tick(self) -> int: ...
    @property
    def dt(self) -> float: ...
    @property
    def bodies(self) -> List[str]: ...
    @property
    def dynamic(self) -> List[bool]: ...
    @property
    def normal_law(self) -> str: ...
    @property
    def friction_model(self) -> str: ...
    def state(self) -> Dict[str, np.ndarray]: ...
    def energy(self) -> Dict[str, float]: ...
    def contact_columns(self) -> Dict[str, np.ndarray]: ...
    def set_drive(self, body: Union[str, int], fx: float, fy: float, tau: float) -> None: ...
    def set_pose(self, body: Union[str, int], x: float, y: float, theta: float) -> None: ...
    def set_velocity(self, body: Union[str, int], vx: float, vy: float, omega: float) -> None: ...

@final
class HapticSystem:
    def __new__(
        cls,
        world: World,
        controller: str,
        device_toml: Optional[str],
        device_source: str,
        hand: str,
        hand_args: List[float],
        passivity: bool,
        slave: Optional[str],
        ramp_time: float,
    ) -> HapticSystem: ...
    def tick(self, encoders: Tuple[float, float, float, float]) -> np.ndarray: ...
    def run_simulated(self, n: int) -> Tuple[Dict[str, np.ndarray], Optional[str]]: ...
    def set_hand(self, hand: str, hand_args: List[float]) -> None: ...
    def plant_encoders(self) -> np.ndarray: ...
    @staticmethod
    def columns() -> List[str]: ...
    def last_record(self) -> Dict[str, float]: ...
    @property
    def safety_trip(self) -> Optional[str]: ...
    @property
    def dt(self) -> float: ...
    @property
    def controller(self) -> str: ...
    @property
    def ramp(self) -> float: ...
    @property
    def device_start(self) -> List[float]: ...
    def world(self) -> World: ...

def wall_run(
    law: str,
    params: List[Tuple[str, float]],
    mass: float,
    damping: float,
    push: float,
    gap0: float,
    v0: float,
    dt: float,
    duration: float,
    integration: str,
    impulse: Optional[Tuple[float, float]],
    passivity: bool,
    per_contact: bool,
) -> Dict[str, Any]: ...
def peg_run(
    model: str,
    params: List[Tuple[str, float]],
    mass: float,
    n_contacts: int,
    f_n: float,
    dt: float,
    duration: float,
    period: float,
    push: Tuple[str, float, float],
    per_contact: bool,
) -> Dict[str, Any]: ...
def model_names() -> Tuple[List[str], List[str]]: ...
def law_params(model: str, per_contact: bool = False) -> List[Dict[str, Any]]: ...
def sweep_task(
    model: str, ks: List[float], bs: List[float], rate_hz: float, duration: float
) -> Dict[str, Any]: ...
def sweep_models() -> List[str]: ...
def reproduce(
    figure: str, out: Union[str, "os.PathLike[str]"]
) -> Tuple[str, float, List[Tuple[str, int, int, int, List[str]]]]: ...
def study_present(
    study: Union[str, "os.PathLike[str]"], condition: str, delta: Optional[float] = None
) -> Tuple[float, List[float], float, str]: ...

def devices() -> List[Dict[str, Any]]: ...
