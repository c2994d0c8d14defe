"""The results table of a sweep, appended one scenario at a time so that a killed sweep keeps
everything it finished.

Parquet: OUT/results.parquet/ is a folder of Parquet files (a dataset pandas and pyarrow read
as one table); every result is written to its own file (written to a temporary name, then
renamed, so a kill never leaves half a file), and at the end of a sweep the files are merged
into one. CSV: OUT/results.csv, one line appended (and flushed to disk) per result; a torn last
line from a kill is dropped when reading.

When a scenario has several rows (it failed, then was re-run), the last one counts.
"""

from __future__ import annotations

import csv
import glob
import io
import json
import os
import uuid

import pandas as pd

from .scenarios import ID

FINISHED = "finished_at"


class ResultStore:
    def __init__(self, out_dir: str, fmt: str = "parquet"):
        if fmt not in ("parquet", "csv"):
            raise ValueError(f"unknown results format {fmt!r} (parquet, csv)")
        self.out_dir = out_dir
        self.fmt = fmt
        os.makedirs(out_dir, exist_ok=True)
        self.path = os.path.join(out_dir, "results.parquet" if fmt == "parquet" else "results.csv")
        if fmt == "parquet":
            os.makedirs(self.path, exist_ok=True)

    # ---- writing ---------------------------------------------------------------------------

    def append(self, row: dict) -> None:
        row = {k: (json.dumps(v) if isinstance(v, (dict, list)) else v) for k, v in row.items()}
        if self.fmt == "parquet":
            name = f"part-{row.get(FINISHED, '')}-{uuid.uuid4().hex[:8]}.parquet".replace(":", "")
            final = os.path.join(self.path, name)
            tmp = os.path.join(self.path, "." + name + ".tmp")
            pd.DataFrame([row]).to_parquet(tmp, index=False)
            os.replace(tmp, final)
            return
        exists = os.path.exists(self.path) and os.path.getsize(self.path) > 0
        header = None
        if exists:
            with open(self.path, newline="") as f:
                header = next(csv.reader(f), None)
        if header is not None and any(k not in header for k in row):
            # a column the file does not have yet (e.g. the first ok row after failures): rewrite
            df = self.read_all()
            df = pd.concat([df, pd.DataFrame([row])], ignore_index=True)
            tmp = self.path + ".tmp"
            df.to_csv(tmp, index=False)
            os.replace(tmp, self.path)
            return
        cols = header or list(row)
        buf = io.StringIO()
        w = csv.DictWriter(buf, fieldnames=cols, extrasaction="raise")
        if header is None:
            w.writeheader()
        w.writerow({c: row.get(c, "") for c in cols})
        with open(self.path, "a", newline="") as f:
            if exists:
                # a kill may have left a torn last line: make sure we start on a new one
                with open(self.path, "rb") as g:
                    g.seek(-1, os.SEEK_END)
                    if g.read(1) != b"\n":
                        f.write("\n")
            f.write(buf.getvalue())
            f.flush()
            os.fsync(f.fileno())

    def compact(self) -> None:
        """Parquet: merge the per-result files into one (no-op for CSV)."""
        if self.fmt != "parquet":
            return
        files = sorted(glob.glob(os.path.join(self.path, "*.parquet")))
        if len(files) <= 1:
            return
        df = self.read_all()
        name = f"merged-{uuid.uuid4().hex[:8]}.parquet"
        tmp = os.path.join(self.path, "." + name + ".tmp")
        df.to_parquet(tmp, index=False)
        os.replace(tmp, os.path.join(self.path, name))
        for f in files:
            os.remove(f)

    # ---- reading ---------------------------------------------------------------------------

    def read_all(self) -> pd.DataFrame:
        """Every row ever written (a scenario may appear more than once)."""
        if self.fmt == "parquet":
            files = sorted(glob.glob(os.path.join(self.path, "*.parquet")))
            if not files:
                return pd.DataFrame()
            return pd.concat([pd.read_parquet(f) for f in files], ignore_index=True)
        if not os.path.exists(self.path) or os.path.getsize(self.path) == 0:
            return pd.DataFrame()
        with open(self.path, newline="") as f:
            text = f.read()
        if not text.endswith("\n"):          # torn last line of a killed sweep
            text = text[: text.rfind("\n") + 1]
        if not text.strip():
            return pd.DataFrame()
        return pd.read_csv(io.StringIO(text), keep_default_na=True)

    def latest(self) -> pd.DataFrame:
        """One row per scenario: its last result."""
        df = self.read_all()
        if df.empty:
            return df
        if FINISHED in df.columns:
            df = df.sort_values(FINISHED, kind="stable")
        return df.drop_duplicates(ID, keep="last").reset_index(drop=True)

    def done_ids(self) -> set:
        df = self.latest()
        if df.empty:
            return set()
        return set(df.loc[df["status"] == "ok", ID])


def open_store(out_dir: str, fmt: str | None = None) -> ResultStore:
    """The store of OUT: the format it already has, else fmt (default parquet)."""
    has_parquet = os.path.isdir(os.path.join(out_dir, "results.parquet"))
    has_csv = os.path.isfile(os.path.join(out_dir, "results.csv"))
    if fmt is None:
        fmt = "csv" if has_csv and not has_parquet else "parquet"
    elif (fmt == "csv" and has_parquet) or (fmt == "parquet" and has_csv):
        raise ValueError(f"{out_dir} already holds results in the other format; use --format "
                         f"{'parquet' if has_parquet else 'csv'} or another folder")
    return ResultStore(out_dir, fmt)
