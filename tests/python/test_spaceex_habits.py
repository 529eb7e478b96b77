"""SpaceEx habits from Python (docs/python.md, docs/spaceex.md): hybrid.load(path, config=...) and
Model.simulate(init=...). Oracles written apart from the module: the time-horizon read from the
.cfg file here, and the closed form x(t) = 2 + (x0 - 2) exp(-t/2) of x' = 1 - x/2."""

import math
import os

import pytest

import hybrid

SOURCE = os.environ.get("HYBRID_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))
FISCHER = os.path.join(SOURCE, "spec", "spaceex", "fischer_2.xml")
FISCHER_CFG = os.path.join(SOURCE, "spec", "spaceex", "fischer_2.cfg")

DECAY = """automaton decay {
  var x in [-10, 10];
  mode m { x' = -0.5 * x + 1; }
  init m { x = 0; }
  scenario { until 3; }
}
system two {
  instance A = decay;
  instance B = decay;
  scenario { until 3; }
}
"""


def time_horizon(cfg_text):
    for line in cfg_text.splitlines():
        if line.startswith("time-horizon"):
            return float(line.split("=", 1)[1])
    raise AssertionError("no time-horizon")


def test_the_configurations_time_horizon_is_the_default_horizon():
    with open(FISCHER_CFG) as f:
        horizon = time_horizon(f.read())
    r = hybrid.load(FISCHER).simulate()
    assert r["status"] == "completed"
    assert r["until"] == horizon and r["time"][-1] == horizon
    assert hybrid.load(FISCHER).simulate(until=1.5)["time"][-1] == 1.5  # until wins


def test_config_selects_another_configuration(tmp_path):
    with open(FISCHER_CFG) as f:
        text = f.read()
    other = tmp_path / "other.cfg"
    other.write_text("\n".join("time-horizon = 4.5" if line.startswith("time-horizon") else line
                               for line in text.splitlines()) + "\n")
    model = hybrid.load(FISCHER, config=other)
    assert model.simulate()["until"] == 4.5
    assert model.check()["properties"][0]["within"] == 4.5
    with pytest.raises(ValueError, match=r"^config names a SpaceEx configuration"):
        hybrid.load(os.path.join(SOURCE, "spec", "thermostat.ha"), config=other)
    bad = tmp_path / "bad.cfg"
    bad.write_text('system = "fischer"\ntime-horizon = later\n')
    with pytest.raises(hybrid.ModelError, match=r"bad\.cfg:2:16: time-horizon: 'later'"):
        hybrid.load(FISCHER, config=bad)


def test_init_sets_a_runs_initial_values(tmp_path):
    path = tmp_path / "decay.ha"
    path.write_text(DECAY)
    model = hybrid.load(path)
    closed = lambda x0: 2.0 + (x0 - 2.0) * math.exp(-1.5)  # noqa: E731
    r = model.simulate(init={"A.x": 5.0})
    assert r["states"]["A.x"][0] == 5.0
    assert abs(r["states"]["A.x"][-1] - closed(5.0)) <= 1e-7
    assert abs(r["states"]["B.x"][-1] - closed(0.0)) <= 1e-7
    # The model itself is unchanged: the next run starts as declared.
    assert model.simulate()["states"]["A.x"][0] == 0.0
    with pytest.raises(ValueError, match=r"^init: 'x' is not a continuous variable .* 'A.x' or "
                                         r"'B.x'"):
        model.simulate(init={"x": 1.0})
    with pytest.raises(ValueError, match=r"^init A.x: 11 lies outside the declared domain "
                                         r"\[-10, 10\]"):
        model.simulate(init={"A.x": 11.0})
    with pytest.raises(ValueError, match=r"finite"):
        model.simulate(init={"A.x": float("nan")})


def test_the_documented_example_prints_what_it_says(tmp_path, monkeypatch, capsys):
    import re
    import shutil
    with open(os.path.join(SOURCE, "docs", "python.md")) as f:
        blocks = re.findall(r"```python\n(.*?)```", f.read(), re.S)
    code = next(b for b in blocks if 'config="short.cfg"' in b)
    shutil.copytree(os.path.join(SOURCE, "spec"), tmp_path / "spec")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "docs/python.md", "exec"), {"__name__": "example"})
    lines = capsys.readouterr().out.splitlines()
    # Both clocks run untouched: P1.x from 2 and P2.x from 0 for 7.5 time units.
    assert lines == ["100.0", "7.5 {'P1.x': 9.5, 'k': 0.0, 'P2.x': 7.5}", "7.5"]
