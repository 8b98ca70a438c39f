"""Studies: when does the local model beat the global one (docs/study.md).

``study(config, out)`` runs a declarative study on every core of this machine, or with
``client=`` (a ``dask.distributed.Client``) on a Dask cluster. The work happens in Rust: the
study is resolved once into a JSON string (it pickles as it is), each case runs in
``perturbid_rs._core.study_case`` on a worker, finished cases are appended to the journal
``out/cases.jsonl`` as they arrive (a rerun skips them), and the report is written from the
journal, so a cluster run and a local run of the same study give the same files.
"""

from __future__ import annotations

import json
import logging
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Mapping, Union

from . import _core

__all__ = ["study", "StudyResult", "run_case"]

log = logging.getLogger("perturbid_rs.study")


@dataclass(frozen=True)
class StudyResult:
    """Where a study wrote its outputs, and its Markdown summary.

    ``results_csv``: the tidy table (one row per case, method, metric and distance);
    ``summary_csv``: medians and 5-95 % intervals over points and seeds; ``figure``: median
    relative RMS error against distance (log axis), its 5-95 % interval shaded; ``parquet``: the results as Parquet (pyarrow), or None.
    """

    out: Path
    summary: str
    results_csv: Path
    summary_csv: Path
    figure: Path
    parquet: Path | None

    def to_dataframe(self) -> Any:
        """The tidy results as a pandas DataFrame (needs pandas)."""
        import pandas as pd  # type: ignore[import-untyped]

        return pd.read_csv(self.results_csv, keep_default_na=False, na_values=[""])


def run_case(study_json: str, index: int) -> str:
    """One case of a resolved study (what a Dask worker runs); its result as JSON."""
    return _core.study_case(study_json, index)


Config = Union[str, "os.PathLike[str]", Mapping[str, Any]]


def _resolve(config: Config) -> str:
    if isinstance(config, Mapping):
        return _core.study_resolve(json.dumps(dict(config)), "json", str(Path.cwd()), "study")
    return _core.study_resolve_file(str(Path(config)))


def study(
    config: Config,
    out: Union[str, "os.PathLike[str]"] = "study",
    *,
    client: Any = None,
    progress: bool = True,
) -> StudyResult:
    """Runs a study and writes its report into ``out``.

    ``config``: a TOML file (path) or the same as a dict (relative files then relative to the
    working directory). ``client``: a ``dask.distributed.Client``; the cases run on its
    workers (each needs perturbid_rs installed), the results come back as they finish and go
    into the journal, so an interrupted cluster run resumes. Without it, every core here.
    ``progress``: log cases done to the logger ``perturbid_rs.study`` (INFO).
    Returns a :class:`StudyResult`.
    """
    resolved = _resolve(config)
    out_path = Path(out)
    if client is None:
        summary = _core.study_run(resolved, str(out_path), progress)
    else:
        summary = _run_on_dask(resolved, out_path, client, progress)
    parquet = None
    try:
        import pyarrow.csv as pacsv  # type: ignore[import-untyped]
        import pyarrow.parquet as pq  # type: ignore[import-untyped]

        table = pacsv.read_csv(out_path / "results.csv")
        parquet = out_path / "results.parquet"
        tmp = out_path / ".results.parquet.tmp"
        pq.write_table(table, tmp)
        os.replace(tmp, parquet)
    except ImportError:
        pass
    return StudyResult(
        out=out_path,
        summary=summary,
        results_csv=out_path / "results.csv",
        summary_csv=out_path / "summary.csv",
        figure=out_path / "error_vs_distance.svg",
        parquet=parquet,
    )


def _run_on_dask(resolved: str, out: Path, client: Any, progress: bool) -> str:
    from dask.distributed import as_completed

    pending = _core.study_pending(resolved, str(out))
    total = _core.study_len(resolved)
    done = total - len(pending)
    batch: list[str] = []

    def record() -> None:
        # finished cases go into the journal in batches, so an interrupted run resumes
        nonlocal done
        _core.study_record(str(out), batch)
        done += len(batch)
        batch.clear()
        if progress:
            log.info("study: %d of %d cases", done, total)

    if pending:
        shipped = client.scatter(resolved, broadcast=True)
        futures = client.map(run_case, [shipped] * len(pending), pending, pure=False)
        for future in as_completed(futures):
            batch.append(future.result())
            if len(batch) >= 8:
                record()
        if batch:
            record()
    return _core.study_finish(resolved, str(out))
