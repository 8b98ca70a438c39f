"""Recordings from and to pandas DataFrames (and through them parquet files, with pyarrow), read
by the same rules as the command line's CSV files."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

import perturbid_rs as pr


def frame_of(count=50, seed=4):
    rng = np.random.default_rng(seed)
    t = np.arange(count) * 1e-3
    q = rng.normal(size=(count, 2))
    tau = rng.normal(size=(count, 2)) * 10
    return t, q, tau


def test_a_recording_round_trips_through_a_dataframe_and_parquet(tmp_path):
    t, q, tau = frame_of()
    rec = pr.Recording(t, q, tau, qd=2 * q, name="D.csv")
    df = rec.to_dataframe()
    assert list(df.columns) == ["t", "q1", "q2", "qd1", "qd2", "tau1", "tau2"]
    np.testing.assert_array_equal(df["tau2"].to_numpy(), tau[:, 1])
    df.to_parquet(tmp_path / "log.parquet")
    back = pr.Recording.from_dataframe(pd.read_parquet(tmp_path / "log.parquet"), ["shoulder", "elbow"], experiment="D")
    for field in ("t", "q", "qd", "tau"):
        np.testing.assert_array_equal(getattr(back, field), getattr(rec, field))
    assert back.qdd is None and back.experiment == "D" and back.name == "dataframe"


def test_a_logger_s_frame_reads_by_joint_names_with_time_as_index_or_timestamps():
    t, q, tau = frame_of()
    joints = ["shoulder", "elbow"]
    # named after the joints, in any order, integer torques (a logger's counts), time as index
    df = pd.DataFrame({"tau_elbow": np.round(tau[:, 1]).astype(np.int32), "q_shoulder": q[:, 0], "q_elbow": q[:, 1], "tau_shoulder": tau[:, 0]}, index=pd.Index(100 + t, name="t"))
    rec = pr.Recording.from_dataframe(df, joints, name="logger")
    np.testing.assert_array_equal(rec.t, 100 + t)
    np.testing.assert_array_equal(rec.q, q)
    np.testing.assert_array_equal(rec.tau[:, 1], np.round(tau[:, 1]))
    # epoch timestamps (tz-aware) as t: seconds from the first, to the nanosecond
    stamps = pd.Timestamp("2026-11-28 12:00:00", tz="UTC") + pd.to_timedelta(np.arange(50) * 1_000_001, unit="ns")
    df = pd.DataFrame({"t": stamps, "q1": q[:, 0], "q2": q[:, 1], "tau1": tau[:, 0], "tau2": tau[:, 1]})
    rec = pr.Recording.from_dataframe(df, joints)
    np.testing.assert_allclose(rec.t, np.arange(50) * 1_000_001 / 1e9, rtol=0, atol=1e-15)
    # a timedelta column (time since start) too
    df["t"] = pd.to_timedelta(np.arange(50) * 2, unit="ms")
    np.testing.assert_allclose(pr.Recording.from_dataframe(df, joints).t, np.arange(50) * 2e-3, rtol=0, atol=1e-15)


@pytest.mark.parametrize(
    "change, expected",
    [
        (lambda df: df.assign(q2=df["q2"].astype(str)), r"column 'q2' holds (object|str) values: expected numbers"),
        (lambda df: df.assign(q2=df["q2"] > 0), r"column 'q2' holds bool values: expected numbers"),
        (lambda df: df.assign(q2=pd.array([None] + [1.0] * 49, dtype="Float64")), r"row 1, column 'q2': NaN is not a finite number"),
        (lambda df: df.assign(q1=pd.Timestamp("2026-01-01") + pd.to_timedelta(df["t"], unit="s")), r"column 'q1' holds datetime64\[ns\] values: expected numbers \(only 't' may hold times\)"),
        (lambda df: df.rename(columns={"tau2": "tau1"}), "column 'tau1' appears twice"),
        (lambda df: df.rename(columns={"tau2": 7}), r"column 5 is named 7 \(int\): expected a name"),
        (lambda df: df.assign(extra=1.0), "unexpected column 'extra'"),
        (lambda df: df.drop(columns="t"), "no column 't'"),
        (lambda df: df.iloc[::-1], "time does not increase at data row 2"),
        (lambda df: df.iloc[:0], "no data rows"),
    ],
)
def test_a_bad_frame_is_named(change, expected):
    t, q, tau = frame_of()
    df = pd.DataFrame({"t": t, "q1": q[:, 0], "q2": q[:, 1], "tau1": tau[:, 0], "tau2": tau[:, 1]})
    with pytest.raises(pr.InputError, match=expected):
        pr.Recording.from_dataframe(change(df), ["shoulder", "elbow"])


def test_something_not_a_frame_is_a_type_error():
    with pytest.raises(TypeError, match="a pandas DataFrame"):
        pr.Recording.from_dataframe({"t": [0.0]}, ["a"])


def test_another_tool_s_log_reads_with_a_column_map_from_a_file_and_a_frame(tmp_path):
    """A UR-style log (stamps in ms, positions in degrees as actual_q_<i>, currents counting
    the other way, target positions and a mode in words beside them) read with columns= and
    ignore_columns= gives the recording it was made from, from a CSV file and from a DataFrame
    alike (src/io/column_map.rs)."""
    t, q, tau = frame_of()
    joints = ["shoulder", "elbow"]
    rec = pr.Recording(t, q, tau)
    df = pd.DataFrame({"timestamp": 1e3 * t, "actual_q_0": np.degrees(q[:, 0]), "actual_q_1": np.degrees(q[:, 1]),
                       "target_q_0": q[:, 0], "target_q_1": q[:, 1],
                       "current_shoulder": -tau[:, 0] / 10, "current_elbow": -tau[:, 1] / 10, "mode": ["RUNNING"] * len(t)})
    path = tmp_path / "ur.csv"
    df.to_csv(path, index=False)
    columns = {"t": "timestamp*ms", "q": "actual_q_{i}*deg", "tau": "current_{joint}*-10"}
    for back in (
        pr.Recording.load(path, joints, columns=columns, ignore_columns=["target_q_*", "mode"]),
        pr.Recording.load(path, joints, columns=[f"{k}={v}" for k, v in columns.items()], ignore_columns=["target_q_*,mode"]),
        pr.Recording.from_dataframe(df, joints, columns=columns, ignore_columns=["target_q_*", "mode"]),
    ):
        for field in ("t", "q", "tau"):
            np.testing.assert_allclose(getattr(back, field), getattr(rec, field), rtol=1e-13, atol=1e-15)
        # the columns left out, in the log's order, as the command line lists them; kept by a slice
        assert back.left_out_columns == ["target_q_0", "target_q_1", "mode"]
        assert back[2:10].left_out_columns == back.left_out_columns
    assert rec.left_out_columns == [] and pr.Recording.load(path, joints, columns=columns, ignore_columns=["target_q_*", "mode", "nothing_*"]).left_out_columns == ["target_q_0", "target_q_1", "mode"]
    # without the mode left out: named, with the way out
    with pytest.raises(pr.InputError, match=r"column 'mode'.*ignore_columns"):
        pr.Recording.load(path, joints, columns=columns, ignore_columns=["target_q_*"])
    with pytest.raises(pr.InputError, match=r"column 'mode' holds .* values: expected numbers"):
        pr.Recording.from_dataframe(df, joints, columns=columns, ignore_columns=["target_q_*"])
    # a map that does not fit: the entry named
    with pytest.raises(pr.InputError, match=r"'q=actual_pos_\{i\}': no column 'actual_pos_0' for q1"):
        pr.Recording.load(path, joints, columns={"t": "timestamp*ms", "q": "actual_pos_{i}"})
    with pytest.raises(pr.InputError, match="the scale 'furlong' is no factor"):
        pr.Recording.from_dataframe(df, joints, columns={"q": "actual_q_{i}*furlong"})
    for wrong in ("t=timestamp", {"t": 1.0}, [1, 2]):
        with pytest.raises(TypeError, match="columns: expected a dict"):
            pr.Recording.load(path, joints, columns=wrong)
