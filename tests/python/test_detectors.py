"""Detector classes from the registry: zero copy, state across calls, the CLI's masks."""

import subprocess
import sys
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import evcorner
from conftest import SAMPLE, cli_detect

INFOS = evcorner.detectors()
NAMES = [d["name"] for d in INFOS]


@pytest.fixture(scope="module")
def events():
    return evcorner.read(SAMPLE)


def cls_of(name):
    info = next(d for d in INFOS if d["name"] == name)
    return getattr(evcorner, info["class_name"])


def test_every_registered_detector_has_a_class():
    assert len(NAMES) >= 7 and "efast" in NAMES
    for info in INFOS:
        cls = getattr(evcorner, info["class_name"])
        assert issubclass(cls, evcorner.Detector) and cls.registry_name == info["name"]
        det = cls(240, 180)
        assert det.name == info["name"] and det.sensor == (240, 180) and det.has_score == info["has_score"]
    assert evcorner.EFast.registry_name == "efast" and evcorner.Harris.registry_name == "harris"


@pytest.mark.parametrize("name", NAMES)
def test_mask_equals_the_cli(name, events, cli, tmp_path):
    summary, cli_mask = cli_detect(cli, SAMPLE, name, tmp_path)
    mask = evcorner.detect(events, name)
    assert mask.dtype == np.uint8 and len(mask) == len(events) == summary["events"]
    np.testing.assert_array_equal(mask, cli_mask)
    assert int(mask.sum()) == summary["corners"]


def test_parameters_reach_the_detector(events, cli, tmp_path):
    summary, cli_mask = cli_detect(cli, SAMPLE, "harris", tmp_path, [("harris-window", 7), ("harris-threshold", 2.5)])
    mask = evcorner.Harris(240, 180, harris_window=7, harris_threshold=2.5).process(events)
    np.testing.assert_array_equal(mask, cli_mask)
    assert not np.array_equal(mask, evcorner.detect(events, "harris"))


@pytest.mark.parametrize("name", NAMES)
def test_chunked_equals_whole(name, events):
    cls = cls_of(name)
    whole = cls(240, 180).process(events)
    det = cls(240, 180)
    cuts = [0, 1, 17, 4000, 4001, 12000, len(events)]
    parts = [det.process(events[a:b]) for a, b in zip(cuts, cuts[1:])]
    np.testing.assert_array_equal(np.concatenate(parts), whole)
    assert det.events == len(events) and det.corners == int(whole.sum())
    if det.has_score:
        m1, s1 = cls(240, 180).process_scored(events)
        det2 = cls(240, 180)
        parts = [det2.process_scored(events[a:b]) for a, b in zip(cuts, cuts[1:])]
        np.testing.assert_array_equal(np.concatenate([p[0] for p in parts]), m1)
        np.testing.assert_array_equal(np.concatenate([p[1] for p in parts]), s1)  # NaN == NaN here
        np.testing.assert_array_equal(m1, whole)


def test_zero_copy_by_pointer(events):
    det = evcorner.EFast(240, 180)
    det.process(events)
    assert det.last_address == events.ctypes.data
    view = events[1000:3000]
    det.reset()  # (the view's events are earlier than the last one processed)
    det.process(view)
    assert det.last_address == events.ctypes.data + 1000 * 16
    out = np.zeros(len(events), np.uint8)
    det.reset()
    assert det.process(events, out=out) is out
    big = np.zeros(len(events) + 10, np.uint8)
    det.reset()
    r = det.process(events, out=big)
    assert np.shares_memory(r, big) and len(r) == len(events)


def test_refuses_instead_of_copying(events):
    det = evcorner.EFast(240, 180)
    with pytest.raises(ValueError, match="strided"):
        det.process(events[::2])
    foreign = np.zeros(4, [("x", "<u2"), ("y", "<u2"), ("p", "<i2"), ("t", "<i8")])
    with pytest.raises(TypeError, match="as_events"):
        det.process(foreign)
    with pytest.raises(TypeError, match="numpy array"):
        det.process([(1, 2, 3, 1)])
    with pytest.raises(ValueError, match="1-D"):
        det.process(events[:10].reshape(2, 5))
    raw = np.zeros(16 * 10 + 8, np.uint8)
    misaligned = raw[4:4 + 160].view(evcorner.EVENT_DTYPE)
    with pytest.raises(ValueError, match="aligned"):
        det.process(misaligned)
    with pytest.raises(TypeError, match="uint8"):
        det.process(events, out=np.zeros(len(events), np.int32))
    ro = np.zeros(len(events), np.uint8)
    ro.flags.writeable = False
    with pytest.raises(ValueError, match="read-only"):
        det.process(events, out=ro)
    with pytest.raises(ValueError, match="elements for"):
        det.process(events, out=np.zeros(3, np.uint8))
    assert det.events == 0  # nothing was processed


def test_bad_events_and_parameters(events):
    bad = events[:5].copy()
    bad["x"][3] = 500
    with pytest.raises(evcorner.InvalidEvent):
        evcorner.EFast(240, 180).process(bad)
    with pytest.raises(ValueError, match="harris_window"):
        evcorner.Harris(240, 180, harris_window=3)
    with pytest.raises(ValueError, match="takes no parameter"):
        evcorner.EFast(240, 180, harris_window=7)
    with pytest.raises(TypeError, match="harris_window"):
        evcorner.Harris(240, 180, harris_window="seven")
    with pytest.raises(ValueError, match="unknown detector"):
        evcorner.detect(events, "nope")
    unscored = [d for d in INFOS if not d["has_score"]]
    if unscored:  # today every registered detector has a score; the refusal stays for one without
        with pytest.raises(TypeError, match="has no score"):
            cls_of(unscored[0]["name"])(240, 180).process_scored(events)


def test_gil_is_released_during_detection(events):
    big = np.concatenate([events] * 40)
    big["t"] += np.repeat(np.arange(40, dtype=np.int64) * 10_000_000, len(events))
    count = [0]
    stop = threading.Event()

    def spin():
        while not stop.is_set():
            count[0] += 1

    det = evcorner.Harris(240, 180)
    th = threading.Thread(target=spin)
    th.start()
    time.sleep(0.05)
    before = count[0]
    det.process(big)
    during = count[0] - before
    stop.set()
    th.join()
    # With the GIL held for the whole call the other thread could not count at all.
    assert during > 1000


def test_label_and_metrics(events):
    mask = evcorner.detect(events, "efast")
    corners = events[mask.view(bool)]
    on_track, info = evcorner.label(corners)
    assert len(on_track) == len(corners) == info["corners"]
    assert int(on_track.sum()) == info["on_track"]
    assert info["ft_percent"] == pytest.approx(evcorner.ft_percent(len(corners), info["on_track"]))
    assert evcorner.reduction_rate(len(events), len(corners)) == pytest.approx(100 * (1 - len(corners) / len(events)))
    with pytest.raises(TypeError):
        evcorner.label(corners, radius=3)


def test_simulate_matches_the_cli(cli, tmp_path):
    import subprocess
    from conftest import SOURCE
    scene = SOURCE / "data" / "scenes" / "square.json"
    events, sensor = evcorner.simulate(str(scene))
    out = tmp_path / "sim.txt"
    subprocess.run([cli, "simulate", str(scene), "-o", str(out)], check=True, capture_output=True)
    np.testing.assert_array_equal(events, evcorner.read(out, sensor=sensor))


# ---------------------------------------------------------------- time order, as the CLI checks it


def backwards_text(previous, t):
    """The reader's words for time going backwards (io::backwards_message)."""
    return f"timestamp goes backwards ({previous - t} us before the previous event)"


@pytest.mark.parametrize("name", NAMES)
def test_reversed_input_refused_with_position(name, events):
    rev = events[::-1].copy()
    k = int(np.flatnonzero(np.diff(rev["t"]) < 0)[0]) + 1  # the first event earlier than the one before it
    det = cls_of(name)(240, 180)
    with pytest.raises(evcorner.InvalidEvent) as e:
        det.process(rev)
    assert str(e.value).startswith(f"events: event {k} (t={rev['t'][k]} x={rev['x'][k]} y={rev['y'][k]} p={rev['p'][k]}): ")
    assert backwards_text(rev["t"][k - 1], rev["t"][k]) in str(e.value)
    assert det.events == 0 and det.last_time is None  # refused before the state was touched
    if det.has_score:
        with pytest.raises(evcorner.InvalidEvent, match=f"event {k} "):
            det.process_scored(rev)
    with pytest.raises(evcorner.InvalidEvent, match=f"event {k} "):
        evcorner.detect(rev, name)
    np.testing.assert_array_equal(det.process(events), cls_of(name)(240, 180).process(events))


def test_one_swapped_pair_names_the_same_event_as_the_cli(events, cli, tmp_path):
    rng = np.random.default_rng(7)
    steps = np.flatnonzero(np.diff(events["t"]) > 0)
    k = int(rng.choice(steps[steps > 10])) + 1  # events[k - 1] is strictly earlier than events[k]
    bad = events.copy()
    bad[[k - 1, k]] = bad[[k, k - 1]]
    path = tmp_path / "swapped.txt"
    evcorner.write(path, bad)
    r = subprocess.run([cli, "detect", str(path), "-o", str(tmp_path / "c.txt")], capture_output=True, text=True)
    assert r.returncode != 0
    cli_words = r.stderr.split(f"{path}:{k + 1}: ")[1].split(":")[0]  # line k + 1 holds bad[k]
    with pytest.raises(evcorner.InvalidEvent) as e:
        evcorner.detect(bad)
    assert str(e.value).startswith(f"events: event {k} ") and str(e.value).endswith(": " + cli_words)


def test_a_chunk_earlier_than_the_previous_one_is_refused(events):
    det = evcorner.EFast(240, 180)
    whole = evcorner.EFast(240, 180).process(events)
    det.process(events[1000:2000])
    assert det.last_time == events["t"][1999]
    with pytest.raises(evcorner.InvalidEvent) as e:
        det.process(events[500:600])
    assert str(e.value).startswith(f"events: event 0 (t={events['t'][500]} ")
    assert backwards_text(events["t"][1999], events["t"][500]) in str(e.value)
    assert "last one of the detector's previous call (event 999 of its stream" in str(e.value)
    assert det.events == 1000
    # A later chunk still goes on from where the stream was; reset() starts a new one.
    ref = evcorner.EFast(240, 180)
    ref.process(events[1000:2000])
    np.testing.assert_array_equal(det.process(events[2000:5000]), ref.process(events[2000:5000]))
    det.reset()
    np.testing.assert_array_equal(det.process(events[:500]), whole[:500])


def test_equal_times_across_chunks_are_in_order(events):
    same = np.flatnonzero(np.diff(events["t"]) == 0)
    assert len(same) > 0
    cut = int(same[len(same) // 2]) + 1  # events[cut - 1].t == events[cut].t
    det = evcorner.Harris(240, 180)
    parts = [det.process(events[:cut]), det.process(events[cut:])]
    np.testing.assert_array_equal(np.concatenate(parts), evcorner.Harris(240, 180).process(events))


# ---------------------------------------------------------------- another thread writing to the array

WRITER = r"""
import sys, threading, time
import numpy as np
import evcorner
name = sys.argv[2]
base = evcorner.read(sys.argv[1])
reps = 100
events = np.concatenate([base] * reps)
span = int(base["t"][-1] - base["t"][0]) + 1
events["t"] += np.repeat(np.arange(reps, dtype=np.int64) * span, len(base))
x, y, t = events["x"].copy(), events["y"].copy(), events["t"].copy()
outcomes = []
for attempt in range(4):
    events["x"], events["y"], events["t"] = x, y, t
    det = evcorner.detectors()  # (keeps the interpreter busy a moment between attempts)
    def spoil():
        time.sleep(0.03 + 0.02 * attempt)
        events["x"] = 65535  # far outside any sensor: an unchecked write there leaves the process's memory
        events["y"] = 65535
        events["t"] = events["t"][::-1].copy()
    th = threading.Thread(target=spoil)
    th.start()
    try:
        evcorner.detect(events, name)
        outcomes.append("done")
    except RuntimeError as e:
        assert "changed after the call checked it" in str(e), e
        outcomes.append("changed")
    except evcorner.InvalidEvent:
        outcomes.append("refused")
    th.join()
print(" ".join(outcomes))
"""


@pytest.mark.parametrize("name", ["harris", "efast"])
def test_another_thread_writing_during_detect_cannot_crash(name, tmp_path):
    # In a child process: a crash there fails this test instead of ending pytest.
    r = subprocess.run([sys.executable, "-c", WRITER, str(SAMPLE), name], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, f"the child ended with {r.returncode}: {r.stderr[-2000:]}"
    outcomes = r.stdout.split()
    assert len(outcomes) == 4
    if name == "harris":  # slow enough (about 0.2 s a call) for the writer to land mid-run
        assert "changed" in outcomes, outcomes


# ---------------------------------------------------------------- copies, pickles, repr


@pytest.mark.parametrize("name", NAMES)
@pytest.mark.parametrize("how", ["copy", "deepcopy", "init"])
def test_a_copy_goes_on_from_the_same_state(name, how, events):
    import copy
    cls = cls_of(name)
    half = len(events) // 2
    det = cls(240, 180)
    first = det.process(events[:half])
    dup = {"copy": copy.copy, "deepcopy": copy.deepcopy, "init": lambda d: type(d).__new__(type(d))}[how](det)
    if how == "init":
        evcorner.Detector.__init__(dup, det)
    assert type(dup) is cls and dup is not det
    assert (dup.events, dup.corners, dup.last_time) == (det.events, det.corners, det.last_time)
    rest_dup = dup.process(events[half:])
    rest = det.process(events[half:])
    np.testing.assert_array_equal(rest_dup, rest)
    np.testing.assert_array_equal(np.concatenate([first, rest]), cls(240, 180).process(events))
    # The copy's state is its own: a copy fed nothing stays where the original was.
    assert (dup.events, dup.corners) == (det.events, det.corners)
    fresh = cls(240, 180)
    fresh.process(events[:half])
    other = copy.deepcopy(fresh)
    fresh.process(events[half:])
    assert other.events == half and other.last_time == events["t"][half - 1]
    if not np.array_equal(cls(240, 180).process(events[half:]), rest):  # the state matters here
        np.testing.assert_array_equal(other.process(events[half:]), rest)


@pytest.mark.parametrize("name", NAMES)
def test_pickle_keeps_the_configuration(name, events):
    import pickle
    info = next(d for d in INFOS if d["name"] == name)
    params = {p["name"]: p["default"] for p in info["params"][:1]}
    det = cls_of(name)(64, 48, **params)
    back = pickle.loads(pickle.dumps(det))
    assert type(back) is type(det) and back.sensor == (64, 48) and back.params == det.params
    base = evcorner.Detector(name, 64, 48, params)
    back = pickle.loads(pickle.dumps(base))
    assert type(back) is evcorner.Detector and back.name == name and back.params == params
    det = cls_of(name)(240, 180)
    det.process(events[:100])
    with pytest.raises(TypeError, match="after it has processed events.*deepcopy"):
        pickle.dumps(det)
    det.reset()
    assert pickle.loads(pickle.dumps(det)).events == 0


def test_repr_names_the_detector_and_its_parameters():
    assert repr(evcorner.EFast(240, 180)) == "EFast(240, 180)"
    det = evcorner.Harris(320, 240, harris_window=7, harris_threshold=2.5)
    assert repr(det) == "Harris(320, 240, harris_window=7, harris_threshold=2.5)"
    assert eval(repr(det), {"Harris": evcorner.Harris}).params == det.params
    assert repr(evcorner.Detector("harris", 10, 20, {"harris_k": 0.05})) == "Detector('harris', 10, 20, {'harris_k': 0.05})"


# ---------------------------------------------------------------- type stubs


def stub_tree(name):
    import ast
    path = Path(evcorner.__file__).parent / name
    assert path.exists(), f"{path} is not installed with the package"
    return ast.parse(path.read_text())


def test_the_package_is_typed_and_its_stubs_are_installed():
    pkg = Path(evcorner.__file__).parent
    assert (pkg / "py.typed").exists()
    for stub in ("__init__.pyi", "_evcorner.pyi", "_detectors.pyi", "_events.pyi"):
        stub_tree(stub)
    # setuptools installs them too (pyproject.toml's package-data).
    from conftest import SOURCE
    tomllib = pytest.importorskip("tomllib")
    data = tomllib.loads((SOURCE / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["evcorner"]
    assert "py.typed" in data and "*.pyi" in data


def test_the_stubs_declare_every_name_and_detector():
    import ast
    tree = stub_tree("_evcorner.pyi")
    declared = {n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))}
    declared |= {t.target.id for t in tree.body if isinstance(t, ast.AnnAssign)}
    public = {k for k in vars(evcorner._evcorner) if not k.startswith("__")}
    assert public <= declared, public - declared
    detector = next(n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Detector")
    methods = {n.name: n for n in detector.body if isinstance(n, ast.FunctionDef)}
    for attr in dir(evcorner.Detector):
        if not attr.startswith("_"):
            assert attr in methods or attr == "registry_name", attr
    assert [a.arg for a in methods["process"].args.args] == ["self", "events", "out"]
    init = stub_tree("__init__.pyi")
    names = {n.name: n for n in init.body if isinstance(n, ast.ClassDef)}
    exported = set()
    for n in init.body:
        if isinstance(n, ast.ImportFrom):
            exported |= {a.asname for a in n.names}
    assert set(evcorner.__all__) <= exported | set(names), set(evcorner.__all__) - exported - set(names)
    for info in INFOS:  # every registered detector, with the registry's keywords and defaults
        cls = names[info["class_name"]]
        init_def = next(n for n in cls.body if isinstance(n, ast.FunctionDef) and n.name == "__init__")
        kw = [a.arg for a in init_def.args.kwonlyargs]
        assert kw == [p["name"] for p in info["params"]], info["name"]
        defaults = [ast.literal_eval(d) for d in init_def.args.kw_defaults]
        assert defaults == [p["default"] for p in info["params"]], info["name"]


def test_metrics_take_counts_by_their_documented_keywords():
    assert evcorner.reduction_rate(n_events=200, n_corners=50) == 75.0
    assert evcorner.ft_percent(n_corners=40, n_on_track=10) == 25.0
    assert evcorner.reduction_rate(0, 0) == 0.0 and evcorner.ft_percent(0, 0) == 0.0


def test_errors_name_python_keywords_not_cli_flags(tmp_path):
    def message(f):
        with pytest.raises(ValueError) as e:
            f()
        assert "--" not in str(e.value), str(e.value)
        return str(e.value)

    assert message(lambda: evcorner.Harris(240, 180, harris_window=3)).startswith("harris_window must be within 5..15")
    assert message(lambda: evcorner.Harris(240, 180, harris_k=float("inf"))).startswith("harris_k must be a finite")
    m = message(lambda: evcorner.EFast(240, 180, harris_window=7))
    assert "takes no parameter harris_window (it takes none)" in m
    m = message(lambda: evcorner.Harris(240, 180, arc_filter=True))
    assert "takes no parameter arc_filter (it takes: harris_window, harris_nl, harris_k, harris_threshold)" in m
    local = [d["name"] for d in INFOS if not d["local"]]
    m = message(lambda: evcorner.detect_file(SAMPLE, threads=2, detector=local[0]))
    assert m.startswith(f"threads: detector '{local[0]}' is not local")
    m = message(lambda: evcorner.detect_file(SAMPLE, tmp_path / "c.aedat4", with_score=True))
    assert m.startswith("with_score: AEDAT 4.0 event packets have no field for a score"), m
    assert message(lambda: evcorner.detect_file(SAMPLE, threads=2, with_score=True)) == \
        "threads: with_score needs one thread"
    assert message(lambda: evcorner.detect_file(SAMPLE, harris_window=4, detector="harris")).startswith(
        "harris_window must be within")


def test_classes_show_the_registry_keywords_in_their_signature():
    import inspect
    types = {"integer": int, "number": float, "true/false": bool}
    for info in INFOS:
        sig = inspect.signature(getattr(evcorner, info["class_name"]))
        params = list(sig.parameters.values())
        assert [p.name for p in params[:2]] == ["width", "height"]
        kw = params[2:]
        assert all(p.kind is inspect.Parameter.KEYWORD_ONLY for p in kw)
        assert [(p.name, p.default, p.annotation) for p in kw] == \
            [(p["name"], p["default"], types[p["type"]]) for p in info["params"]]


def test_detect_file_leaves_no_output_after_damaged_input(tmp_path):
    lines = SAMPLE.read_text().splitlines(keepends=True)[:500]
    bad = tmp_path / "bad.txt"
    bad.write_text("".join(lines) + "1.0 x y 1\n")
    out, mask = tmp_path / "c.npy", tmp_path / "m.txt"
    with pytest.raises(evcorner.InputError, match=r"bad\.txt:501:"):
        evcorner.detect_file(bad, out, mask=mask)
    assert not out.exists() and not mask.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.txt"]  # no temporary file either
    s = evcorner.detect_file(bad, out, mask=mask, allow_damaged=True)
    assert s["events"] == 500 and ":501:" in s["damaged"]
    assert len(evcorner.read(out)) == s["corners"] and len(mask.read_text().splitlines()) == 500
    with pytest.raises(ValueError, match="its folder .*missing does not exist"):
        evcorner.detect_file(SAMPLE, tmp_path / "missing" / "c.txt")
