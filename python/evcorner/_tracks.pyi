from typing import Any, Dict, Optional, Tuple

import numpy as np
import numpy.typing as npt

TRACK_DTYPE: np.dtype[np.void]
TRACKERS: Tuple[str, ...]

class Tracker:
    def __init__(self, name: str = ..., *, seeds: Optional[Any] = ..., detector: Optional[str] = ...,
                 init: str = ..., width: int = ..., height: int = ..., seed_radius: float = ...,
                 max_tracks: int = ..., max_idle_ms: Optional[float] = ...,
                 min_separation: Optional[float] = ...) -> None: ...
    def process(self, events: Any) -> npt.NDArray[np.void]: ...
    def stats(self) -> Dict[str, int]: ...

def track(events: Any, tracker: str = ..., *, seeds: Optional[Any] = ..., detector: Optional[str] = ...,
          **kwargs: Any) -> npt.NDArray[np.void]: ...

def eval_tracks(pred: Any, gt: Any, *, asynchronous: bool = ..., associate_px: Optional[float] = ...,
                seeds: Optional[Any] = ..., align: bool = ...) -> Dict[str, Any]: ...
def track_statistics(tracks: Any) -> Dict[str, Any]: ...
