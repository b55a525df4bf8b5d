# Types of the package `evcorner`. The detector classes are generated from the C++
# registry at import; they are declared here with the registry's keywords and defaults
# (a test checks this file against evcorner.detectors()).
from typing import List

from ._detectors import DETECTOR_CLASSES as DETECTOR_CLASSES
from ._detectors import detect as detect
from ._detectors import detect_file as detect_file
from ._detectors import detectors as detectors
from ._detectors import evaluate_truth as evaluate_truth
from ._detectors import label as label
from ._detectors import simulate as simulate
from ._evcorner import EVENT_DTYPE as EVENT_DTYPE
from ._tracks import TRACK_DTYPE as TRACK_DTYPE
from ._tracks import TRACKERS as TRACKERS
from ._tracks import Tracker as Tracker
from ._tracks import eval_tracks as eval_tracks
from ._tracks import track_statistics as track_statistics
from ._tracks import track as track
from ._evcorner import INPUT_FORMATS as INPUT_FORMATS
from ._evcorner import OUTPUT_FORMATS as OUTPUT_FORMATS
from ._evcorner import Detector as Detector
from ._evcorner import InputError as InputError
from ._evcorner import InvalidEvent as InvalidEvent
from ._evcorner import OutputError as OutputError
from ._evcorner import StateTooLarge as StateTooLarge
from ._evcorner import ft_percent as ft_percent
from ._evcorner import reduction_rate as reduction_rate
from ._events import EventFile as EventFile
from ._events import Events as Events
from ._events import as_events as as_events
from ._events import open as open
from ._events import read as read
from ._events import write as write

__version__: str
__all__: List[str]

class EFast(Detector):
    """eFAST (Mueggler et al., BMVC 2017): arcs on the SAE circles of radius 3 and 4"""
    def __init__(self, width: int, height: int) -> None: ...

class Harris(Detector):
    """spatially-adaptive Harris (Mueggler et al., BMVC 2017, Sec. 3.2): newest Nl pixels of the window"""
    def __init__(self, width: int, height: int, *, harris_window: int = 9, harris_nl: int = 25, harris_k: float = 0.04, harris_threshold: float = 8.0) -> None: ...

class HarrisGlobal(Detector):
    """event-based Harris (Vasco et al., IROS 2016): newest N pixels of the sensor"""
    def __init__(self, width: int, height: int, *, harris_window: int = 9, harris_k: float = 0.04, harris_threshold: float = 8.0, harris_n: int = 1000) -> None: ...

class ArcStar(Detector):
    """Arc* (Alzugaray and Chli, RA-L 2018): 50 ms filter, then its arc test on the radius-3/4 circles, majority arcs included"""
    def __init__(self, width: int, height: int, *, arc_filter: bool = True, arc_filter_us: int = 50000, arc_minority_only: bool = False, arc_zero_init: bool = False) -> None: ...

class FaHarris(Detector):
    """FA-Harris (Li et al., IROS 2019): Arc* candidates refined by the adaptive Harris on the newest filtered pixels"""
    def __init__(self, width: int, height: int, *, arc_filter: bool = True, arc_filter_us: int = 50000, arc_minority_only: bool = False, arc_zero_init: bool = False, harris_window: int = 9, harris_nl: int = 25, harris_k: float = 0.04, harris_threshold: float = 8.0) -> None: ...

class EFastHarris(Detector):
    """eFAST -> Harris cascade (Mueggler et al., BMVC 2017, Sec. 4): eFAST corners the adaptive Harris also scores above its threshold"""
    def __init__(self, width: int, height: int, *, harris_window: int = 9, harris_nl: int = 25, harris_k: float = 0.04, harris_threshold: float = 8.0) -> None: ...

class LuvHarris(Detector):
    """luvHarris (Glover et al., TPAMI 2021): TOS surface, Harris table refreshed at fixed points of the stream (reproducible)"""
    def __init__(self, width: int, height: int, *, luv_tos_size: int = 7, luv_tos_threshold: int = 2, luv_gradient: int = 5, luv_block: int = 5, luv_gaussian_block: bool = False, luv_k: float = 0.04, luv_refresh_us: int = 1000, luv_refresh_events: int = 0, luv_adaptive: bool = True, luv_sigmas: float = 2.0, luv_alpha: float = 0.001, luv_threshold: float = 1000000.0, luv_replicate_border: bool = False) -> None: ...
