"""Studies from Python: on every core here, and on a Dask LocalCluster with the same files."""

from __future__ import annotations

from pathlib import Path

import pytest

import perturbid_rs as pr

STUDY = {
    "name": "dask test",
    "seeds": 2,
    "methods": ["local_separated", "direct_ols"],
    "robots": [{"name": "a465"}],
    "sample_points": {"count": 1, "speed_classes": ["fast"]},
    "direct": {"max_evaluations": 30, "periods": 1},
    "evaluation": {"distances": [1, 2], "samples": 4},
}


def test_study_locally_and_on_a_dask_cluster_give_the_same_files(tmp_path: Path):
    distributed = pytest.importorskip("dask.distributed")
    here = pr.study(STUDY, tmp_path / "here")
    assert isinstance(here, pr.StudyResult) and "| local_separated |" in here.summary
    df = here.to_dataframe()
    assert set(df["method"]) == {"local_separated", "direct_ols"} and set(df["seed"]) == {0, 1}
    assert here.parquet is not None and here.parquet.exists()
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        with distributed.Client(cluster) as client:
            there = pr.study(STUDY, tmp_path / "there", client=client)
    for name in ["results.csv", "summary.csv", "summary.md"]:
        assert (here.out / name).read_text() == (there.out / name).read_text(), name


def test_study_errors_and_resume(tmp_path: Path):
    with pytest.raises(pr.InputError, match="seeds"):
        pr.study({**STUDY, "seeds": 0}, tmp_path / "x")
    with pytest.raises(pr.InputError, match="unknown field"):
        pr.study({**STUDY, "sedes": 1}, tmp_path / "x")
    toml = tmp_path / "s.toml"
    toml.write_text('name = "t"\n[[robots]]\nname = "a465"\n[sample_points]\ncount = 1\nspeed_classes = ["fast"]\n'
                    '[direct]\nmax_evaluations = 30\nperiods = 1\n[evaluation]\ndistances = [1]\nsamples = 2\n'
                    'methods = ["local_separated"]\n')
    with pytest.raises(pr.InputError, match=r"s\.toml:13:1: unknown field `methods`"):
        pr.study(toml, tmp_path / "y")  # methods after [evaluation] belongs to that table
    toml.write_text(toml.read_text().replace('methods = ["local_separated"]\n', ""))
    huge = tmp_path / "huge.toml"  # the TOML parser would hold gigabytes of it
    huge.write_text(toml.read_text() + "junk = [" + "{a=1}," * 400_000 + "]\n")
    with pytest.raises(pr.InputError, match=r"huge\.toml: \d+ bytes; a pipeline or study file is read up to 1024 KiB"):
        pr.study(huge, tmp_path / "z")
    with pytest.raises(pr.FileError, match=r"nowhere\.toml"):
        pr.study(tmp_path / "nowhere.toml", tmp_path / "z")
    first = pr.study(toml, tmp_path / "y")
    journal = (tmp_path / "y" / "cases.jsonl").read_text()
    again = pr.study(toml, tmp_path / "y")
    assert (tmp_path / "y" / "cases.jsonl").read_text() == journal  # nothing rerun
    assert first.results_csv.read_text() == again.results_csv.read_text()


def test_the_console_script_runs_a_study_on_a_dask_scheduler(tmp_path: Path):
    """`perturbid study STUDY.toml --scheduler ADDRESS` (the pip-installed script) runs the
    cases on that cluster and writes what a local run writes."""
    import subprocess
    import sysconfig

    distributed = pytest.importorskip("dask.distributed")
    toml = tmp_path / "s.toml"
    toml.write_text('name = "cli"\nseeds = 1\nmethods = ["local_separated"]\n[[robots]]\nname = "a465"\n'
                    '[sample_points]\ncount = 1\nspeed_classes = ["fast"]\n[evaluation]\ndistances = [1]\nsamples = 2\n')
    exe = Path(sysconfig.get_path("scripts")) / "perturbid"
    here = pr.study(toml, tmp_path / "here")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cluster:
        out = subprocess.run([str(exe), "study", str(toml), "--out", str(tmp_path / "there"), "--scheduler", cluster.scheduler_address],
                             capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "wrote results.csv" in out.stdout
    assert (tmp_path / "there" / "results.csv").read_text() == here.results_csv.read_text()
    bad = subprocess.run([str(exe), "study", str(toml), "--scheduler", "tcp://127.0.0.1:9"], capture_output=True, text=True, cwd=tmp_path)
    assert bad.returncode == 1 and bad.stderr.startswith("perturbid: cannot reach the Dask scheduler"), bad.stderr


def test_global_linear_model_as_a_table():
    import numpy as np

    robot = pr.robots.a465()
    rng = np.random.default_rng(0)
    q, qd, qdd = rng.uniform(-1, 1, (3, 200, 6))
    op = pr.OperatingPoint(q[0], qd[0], qdd[0])
    g = pr.identify_global_linear(op, q, qd, qdd, robot.rnea(q, qd, qdd))
    df = g.to_dataframe()
    assert list(df.columns) == ["term", "torque", "joint", "value", "std"] and len(df) == 6 + 3 * 36
    np.testing.assert_array_equal(df[df.term == "T"]["value"].to_numpy(), g.torque)
    d = df[df.term == "D"]
    np.testing.assert_array_equal(d["value"].to_numpy(), g.D.ravel())
    np.testing.assert_array_equal(d["std"].to_numpy(), g.stderr["D"].ravel())
