"""The C host's configuration (hostc/config.c) against the Python host's: the configuration
`mobigrasp run` gives the host (services/run_job.py host_config) read by both gives the same
task parameters (host/app_factory.py build_host_app: TaskParams.for_method with the paper
parameters mapped by the method's paper_to_task and the task settings) and, for 000 and 001, the
same planner parameters (Params000 as plan_000 rounds them, planner_params_001 as the C's
integers, tests/plan001_c.py); a configuration the Python host refuses
(tools/commands/host.py: mcu_sim.world.scenario.parse_host_config) the C refuses naming the
same key."""

from __future__ import annotations

import json
from decimal import Decimal

import pytest
from hypothesis import given
from hypothesis import strategies as st
from plan001_c import params_c
from property_examples import examples
from test_hostc_planning import _params000_c
from test_hostc_replan import _board
from test_hostc_task000 import _c_task

from mobigrasp import hostc
from mobigrasp.host.app_factory import task_params
from mobigrasp.host.planning.bezier000 import Params000
from mobigrasp.host.planning.replan import Replanner
from mobigrasp.host.search import SearchParams
from mobigrasp.host.task import REGISTRY, Task, method_rules
from mobigrasp.host.task.method001 import planner_params_001
from mobigrasp.mcu_sim.world.scenario import ScenarioError, parse_host_config
from mobigrasp.services.run_job import host_config, resolve_scenario

FFI, C = hostc.lib()
WHY = 512


def _parse(cfg) -> tuple:
    """The C's reading of a configuration: (config, None) or (None, why)."""
    text = json.dumps(cfg).encode()
    c, why = FFI.new("mg_config_t *"), FFI.new("char[]", WHY)
    if C.mg_config_parse(text, len(text), c, why, WHY) != 0:
        return None, FFI.string(why).decode()
    return c, None


def _plain(v):
    """A cdata struct or array as plain Python values."""
    kind = FFI.typeof(v).kind if isinstance(v, FFI.CData) else None
    if kind == "struct":
        return {f: _plain(getattr(v, f)) for f, _ in FFI.typeof(v).fields}
    if kind == "array":
        return [_plain(x) for x in v]
    return v


def _search(d: dict) -> SearchParams:
    """The C's search parameters as the search takes them (mg_search_init clamps and
    deduplicates the coarse levels, as SearchParams does)."""
    d = dict(d)
    d["coarse_theta2_mrad"] = tuple(d["coarse_theta2_mrad"][:d.pop("n_coarse")])
    return SearchParams(**d)


def _python_task(cfg: dict) -> Task:
    """The Python host's task of a configuration (host/app_factory.py build_host_app)."""
    method = cfg.get("method", "000")
    params = task_params(method, dict(cfg.get("params", {})))
    for key, value in dict(cfg.get("task", {})).items():
        params[key] = tuple(value) if isinstance(value, list) else value
    return Task(method=method, params=params)


def _same_task_params(cfg: dict) -> None:
    """The C's task parameters of cfg are the Python task's, field by field (and 000's
    planner parameters)."""
    c, why = _parse(cfg)
    assert why is None, why
    p = FFI.new("mg_task_params_t *")
    assert C.mg_config_task_params(c, p) == 0
    py = _python_task(cfg)
    c_task = _c_task(py, method=py.method)  # the Python's fields in the C's struct
    want = _plain(c_task.p)
    got = _plain(p[0])
    if py.method == "002":  # the helper leaves the fuzzy table at the row's: compared below
        got.pop("fuzzy"), want.pop("fuzzy")
    got["search"], want["search"] = _search(got["search"]), _search(want["search"])
    assert got == want
    if py.method == "002":  # the fuzzy table (test_hostc_task000's helper leaves it)
        from mobigrasp.host.control.fuzzy import FuzzyParams
        fz = FuzzyParams(**py.p.fuzzy)
        assert {f: getattr(p.fuzzy, f) for f, _ in FFI.typeof("mg_fuzzy_params_t").fields} \
            == {f: getattr(fz, f) for f, _ in FFI.typeof("mg_fuzzy_params_t").fields}
        assert p.t_d_px == py.p.t_d_px
    if py.method == "000":
        pl, v_limit = FFI.new("mg_params000_t *"), FFI.new("int32_t *")
        C.mg_config_params000(c, p, pl, v_limit)
        pp = Params000(**{"standoff_m": py.p.approach_standoff_mm / 1000, **py.p.planner})
        want_pl = _params000_c(pp)[0]
        for f, _ in FFI.typeof("mg_params000_t").fields:
            g = getattr(pl, f)
            assert (list(g) if not isinstance(g, int) else g) == (
                list(getattr(want_pl, f)) if not isinstance(g, int) else getattr(want_pl, f)), f
        assert v_limit[0] == int(round(pp.v_max * 1000))
    if py.method == "001":
        pl, v_limit = FFI.new("mg_params001_t *"), FFI.new("int32_t *")
        C.mg_config_params001(c, p, pl, v_limit)
        pp = planner_params_001(py.p)
        assert _plain(pl[0]) == _plain(params_c(pp)[0])
        assert v_limit[0] == int(round(pp.v_max * 1000))
        b = FFI.new("mg_board_replanner001_t *")
        C.mg_config_replanner001(c, p, b)
        want_b = _board(Replanner((0.0, 0.0), pp), pp.v0)
        for f in ("params", "cfg", "v_limit_mm_s"):
            assert _plain(getattr(b, f)) == _plain(getattr(want_b, f)), f
        assert list(b.level_v0_mm_s)[:2] == list(want_b.level_v0_mm_s)[:2]


@pytest.mark.parametrize("name", ["paper000-exp1", "paper000-exp2", "paper001-sim1",
                                  "paper001-sim2", "paper002-marker", "paper002-cylinder-moving"])
def test_the_shipped_scenarios_configurations(name):
    """What `mobigrasp run` gives the host of each shipped scenario: the same parameters."""
    _, scenario = resolve_scenario(name)
    cfg = host_config(scenario)
    _same_task_params(cfg)
    c, _ = _parse(cfg)
    assert FFI.string(c.method).decode() == scenario.meta.method
    assert c.f_px == int(round(cfg["camera"]["f_px"]))
    assert (c.u0_px, c.v0_px) == (int(round(cfg["camera"]["u0_px"])),
                                  int(round(cfg["camera"]["v0_px"])))


@given(st.integers(0, 640).map(lambda k: k / 2), st.integers(0, 480).map(lambda k: k / 2))
def test_the_principal_point_is_read_as_the_python_rounds_it(u0, v0):
    """u0_px and v0_px, halves to even as Python's round (host/app_factory.py); 160, 120
    without them."""
    c, why = _parse({"method": "002", "camera": {"f_px": 500.0, "u0_px": u0, "v0_px": v0}})
    assert why is None, why
    assert (c.f_px, c.u0_px, c.v0_px) == (500, int(round(u0)), int(round(v0)))
    c, _ = _parse({"method": "002", "camera": {"f_px": 500.0}})
    assert (c.u0_px, c.v0_px) == (160, 120)


def _values(method: str):
    """Any value in range of each of the method's paper parameters (its kind's), as a
    configuration's params (some of them); decimals as a file would give them."""
    table = method_rules(method).paper_params
    strategies = {}
    for name, p in table.items():
        if p.kind is int:
            strategies[name] = st.integers(int(p.lo), int(p.hi))
        else:
            whole = st.integers(int(-(-p.lo // 1)), int(p.hi // 1)).map(float) \
                if -(-p.lo // 1) <= p.hi // 1 else st.nothing()
            strategies[name] = st.one_of(
                whole,
                st.decimals(Decimal(repr(p.lo)), Decimal(repr(p.hi)), places=4).map(float),
                st.floats(p.lo, p.hi, allow_nan=False))
    return st.fixed_dictionaries({}, optional=strategies)


def _python_refuses(cfg: dict) -> str | None:
    """The key the Python host's check names (None: accepted)."""
    try:
        parse_host_config(cfg, "<cfg>", methods=REGISTRY)
    except ScenarioError as exc:
        return str(exc).split(": ")[1]
    try:
        _python_task(cfg)
    except ValueError as exc:
        return str(exc)
    return None


@examples(150)
@given(st.sampled_from(["000", "001", "002"]).flatmap(
    lambda m: st.tuples(st.just(m), _values(m))),
    st.none() | st.dictionaries(st.sampled_from(["SEARCH", "ADJUST", "LOST", "LIFT"]),
                                st.integers(1, 3_600_000_000), max_size=2),
    st.none() | st.sampled_from([[], [1200, -300]]))
def test_any_configuration_in_range(named, timeouts, object_xy):
    """Paper parameters of any value in their ranges, task settings: both hosts accept or
    refuse it alike, and the C's task parameters are the Python's."""
    method, params = named
    cfg: dict = {"method": method, "params": params, "camera": {"f_px": 611.0}}
    task: dict = {}
    if timeouts is not None:
        task["timeouts_us"] = timeouts
    if object_xy is not None:
        task["object_xy_mm"] = object_xy
    if task:
        cfg["task"] = task
    refused = _python_refuses(cfg)
    c, why = _parse(cfg)
    if refused is not None:  # an ordered pair out of order
        assert why is not None and why.split(":")[0] == refused.split(":")[0], (why, refused)
        return
    assert why is None, why
    _same_task_params(cfg)


@pytest.mark.parametrize("cfg, key", [
    ({"method": "000", "params": {"k9": 1.0}}, "params.k9"),
    ({"method": "000", "params": {"k1": 11.0}}, "params.k1"),
    ({"method": "000", "params": {"k1": True}}, "params.k1"),
    ({"method": "000", "params": {"k_theta2": -1.0}}, "params.k_theta2"),  # eq. (10): gains >= 0
    ({"method": "000", "params": {"w_min": 20.0}}, "params.w_min"),
    ({"method": "000", "params": {"w_min": 50}}, "params.w_min"),
    ({"method": "000", "params": {"theta2_min": -2.2, "theta2_max": -2.205}},
     "params.theta2_min"),
    ({"method": "002", "params": {"T_s": 0.3}}, "params.T_s"),
    ({"method": "000", "paramz": {}}, "paramz"),
    ({"method": "000", "task": {"timeout_us": {}}}, "task.timeout_us"),
    ({"method": "000", "task": {"timeouts_us": {"SEARCH": 0}}}, "task.timeouts_us.SEARCH"),
    ({"method": "000", "task": {"object_xy_mm": [1]}}, "task.object_xy_mm"),
    ({"method": "000", "camera": {"u0_px": -0.5}}, "camera.u0_px"),
    ({"method": "000", "camera": {"v0_px": 240.5}}, "camera.v0_px"),
    ({"method": "000", "camera": {"u0_px": "160"}}, "camera.u0_px"),
])
def test_a_bad_configuration_is_refused_by_its_key(cfg, key):
    """Unknown keys, values out of range or of the wrong kind, pairs out of order: refused by
    both, the C naming the key the Python names."""
    assert _python_refuses(cfg) is not None
    c, why = _parse(cfg)
    assert c is None and why.split(": ")[0] == key, why


@pytest.mark.parametrize("text, e9", [
    ("0.3", 300000000), ("-2.8", -2800000000), ("1e-3", 1000000), ("2.5E+0", 2500000000),
    ("0.0000000005", 0), ("0.0000000015", 2), ("0.30000000000000004", 300000000),
    ("20", 20 * 10**9), ("7.0000000005", 7000000000)])
def test_numbers_are_read_exactly(text, e9):
    """A number's decimal text in billionths, a tie past the ninth decimal to even."""
    # a gain of eq. (10) in [0, 10] for the positive ones, alpha_T in [-pi, 0] for the negative
    name, index, lo, hi = ("k_theta3", 10, 0, 10 * 10**9) if e9 >= 0 else \
        ("alpha_T", 12, -3141592653, 0)
    raw = b'{"method": "000", "params": {"' + name.encode() + b'": ' + text.encode() + b"}}"
    c, w = FFI.new("mg_config_t *"), FFI.new("char[]", WHY)
    ok = C.mg_config_parse(raw, len(raw), c, w, WHY) == 0
    if not lo <= e9 <= hi:
        assert not ok
        return
    assert ok, FFI.string(w)
    assert c.value_e9[index] == e9
