from os import PathLike
from typing import Any, Dict, List, Literal, Optional, Tuple, Type, Union, overload

from ._evcorner import Detector, Events, Mask, ParamValue, Scores

Path = Union[str, "PathLike[str]"]

DAVIS240: Tuple[int, int]
DETECTOR_CLASSES: Dict[str, Type[Detector]]

def detectors() -> List[Dict[str, Any]]: ...
@overload
def detect(events: Events, detector: str = ..., sensor: Union[Tuple[int, int], str] = ..., scores: Literal[False] = ...,
           out: Optional[Mask] = ..., **params: ParamValue) -> Mask: ...
@overload
def detect(events: Events, detector: str = ..., sensor: Union[Tuple[int, int], str] = ..., *, scores: Literal[True],
           out: Optional[Mask] = ..., **params: ParamValue) -> Tuple[Mask, Scores]: ...
def detect_file(input: Path, output: Optional[Path] = None, detector: str = "efast", mask: Optional[Path] = None,
                format: str = "auto", to: str = "auto", with_score: bool = False, threads: int = 1,
                allow_damaged: bool = False, reader: Optional[Dict[str, Any]] = None,
                **params: ParamValue) -> Dict[str, Any]: ...
def label(corners: Events, **ft_params: Any) -> Tuple[Mask, Dict[str, Any]]: ...
def simulate(scene: Union[Path, str]) -> Tuple[Events, Tuple[int, int]]: ...
def evaluate_truth(events: Optional[Events], corners: Any, truth: Path, radius: float = 3.5, tolerance_us: int = 1000,
                   credit: str = "all", interpolation: str = "linear",
                   speed_bins: Optional[List[float]] = None) -> Dict[str, Any]: ...
