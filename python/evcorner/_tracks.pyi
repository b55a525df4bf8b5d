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
