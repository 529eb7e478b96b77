"""Runs the worked example of docs/python.md as it stands (from the repository's root, in a
temporary working copy of the paths it reads), so the documentation cannot drift from the
module."""

import os
import re
import shutil

SOURCE = os.environ.get("HYBRID_SOURCE_DIR", os.path.join(os.path.dirname(__file__), "..", ".."))


def example_code():
    with open(os.path.join(SOURCE, "docs", "python.md")) as f:
        text = f.read()
    section = text[text.index("## A worked example"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_worked_example_runs(tmp_path, monkeypatch, capsys):
    shutil.copytree(os.path.join(SOURCE, "spec"), tmp_path / "spec")
    monkeypatch.chdir(tmp_path)
    exec(compile(example_code(), "docs/python.md", "exec"), {"__name__": "example"})
    out = capsys.readouterr().out
    assert "free finger at g = 255: [ 70.  90. -55.]" in out
    assert "link 1 blocked at 80: [40. 90. 43.]" in out
    assert "first at t = 2.2314" in out
    try:
        import matplotlib  # noqa: F401
        assert (tmp_path / "python_example.png").stat().st_size > 0
    except ImportError:
        pass


def test_gripper_example_runs(capsys):
    with open(os.path.join(SOURCE, "docs", "python.md")) as f:
        text = f.read()
    section = text[text.index("## The gripper where a robot program uses it"):]
    code = re.search(r"```python\n(.*?)```", section, re.S).group(1)
    exec(compile(code, "docs/python.md", "exec"), {"__name__": "example"})
    out = capsys.readouterr().out
    assert "clamped: ['finger_1_joint_3', 'finger_2_joint_3', 'finger_middle_joint_3']" in out
    assert "gSTA 2 finger A at [21.4039  0.     43.    ]" in out
    assert "held:" in out
