"""Scenes from Python against the `conform` command."""
import json
import subprocess

import pytest

import conform

# The cut scene with its cut moved into the first steps, so that a short run cuts.
CUT_SETS = {"cut.at": 0.02, "physics.substeps": 1}
CUT_STEPS = 4


def cli_run(exe, scene, out, steps, sets):
    args = [exe, "run", scene, "--out", str(out), "--steps", str(steps), "--no-render"]
    for k, v in sets.items():
        args += ["--set", f"{k}={json.dumps(v) if not isinstance(v, str) else v}"]
    done = subprocess.run(args, capture_output=True, text=True)
    return done, out / "summary.json"


def test_builtin_scenes_are_listed():
    names = conform.scenes()
    assert "tear-opening" in names and "cut" in names and "drill" in names
    assert json.loads(conform.scene_json("cut"))["scene"] == "cut"


def test_run_metrics_equal_the_cli(conform_exe, tmp_path):
    done, summary_file = cli_run(conform_exe, "cut", tmp_path / "cli", CUT_STEPS, CUT_SETS)
    assert done.returncode == 0, done.stderr
    cli = json.loads(summary_file.read_text())
    py = conform.run("cut", out=tmp_path / "py", set=CUT_SETS, steps=CUT_STEPS, render=False)
    assert py["metrics"] == cli["metrics"]
    assert py["metrics"]["pieces"] == 2  # the cut happened within the run
    assert json.loads((tmp_path / "py" / "summary.json").read_text())["metrics"] == py["metrics"]


def test_run_without_out_leaves_nothing_and_returns_the_summary():
    summary = conform.run("cut", steps=2, set={"cut.at": 0.01}, render=False)
    assert summary["metrics"]["nodes"] > 0


def test_bad_scene_key_raises_scene_error_with_the_cli_message(conform_exe, tmp_path):
    done, _ = cli_run(conform_exe, "cut", tmp_path / "cli", 2, {"physics.dt": -1})
    assert done.returncode == 2
    with pytest.raises(conform.SceneError) as e:
        conform.run("cut", set={"physics.dt": -1}, steps=2)
    assert isinstance(e.value, ValueError)
    assert str(e.value).startswith("key 'physics.dt', value -1")
    assert str(e.value) in done.stderr
    assert not (tmp_path / "cli").exists()


def test_unknown_scene_raises_with_the_library_message(conform_exe):
    done = subprocess.run([conform_exe, "run", "no-such-scene", "--steps", "1"],
                          capture_output=True, text=True)
    with pytest.raises(RuntimeError) as e:
        conform.run("no-such-scene", steps=1)
    assert str(e.value) and str(e.value) in done.stderr


def test_sweep_points_equal_single_runs(tmp_path):
    rows = conform.sweep("cut", grid={"physics.substeps": [1, 2]}, set={"cut.at": 0.02},
                         steps=3, out=tmp_path / "sweep")
    assert [r["values"]["physics.substeps"] for r in rows] == ["1", "2"]
    assert (tmp_path / "sweep" / "runs" / "00001" / "summary.json").exists()
    single = conform.run("cut", set={"cut.at": 0.02, "physics.substeps": 2}, steps=3,
                         render=False)
    assert rows[1]["summary"]["metrics"] == single["metrics"]
    assert rows[0]["summary"]["metrics"] != rows[1]["summary"]["metrics"]
