"""A sweep written a chunk at a time: CSV (the rows of report.sweep_csv) and Parquet (pyarrow).

Each chunk (a SweepResult with its MotionAlong) is appended and let go, so a sweep of millions
of steps is written in bounded memory.  The CSV is the one ``sweep --csv`` writes in memory, row
for row; the Parquet file has the same columns (``step`` int64, the others float64), one row
group per chunk.  pyarrow is optional: without it, asking for Parquet is a usage error.
"""

from __future__ import annotations

import numpy as np

from ..errors import UsageError
from .outfile import OutputFile, WholeOrNothing
from .report import sweep_columns, sweep_csv

__all__ = ["SweepWriter", "parquet_available"]


def parquet_available() -> bool:
    try:
        import pyarrow
        import pyarrow.parquet  # noqa: F401
    except ImportError:
        return False
    return True


class SweepWriter(WholeOrNothing):
    """Appends chunks of a sweep to ``csv`` and/or ``parquet`` (paths; None: not written), each through
    present/outfile.OutputFile: written as PATH.<random>.partial and renamed once the sweep is whole."""

    def __init__(self, csv: str | None = None, parquet: str | None = None) -> None:
        if parquet:
            self.require_parquet(parquet)
        self._csv_path, self._csv = csv, None  # (opened at the first chunk: a sweep refused writes nothing)
        self._parquet_path, self._pq, self._pq_file = parquet, None, None
        self.rows = 0

    @staticmethod
    def require_parquet(path: str) -> None:
        """Refuse --parquet without pyarrow (a usage error naming it)."""
        if not parquet_available():
            raise UsageError(f"--parquet {path}: writing Parquet needs pyarrow (pip install pyarrow); "
                             "--csv writes the same columns")

    def write(self, res, motion=None) -> None:
        """Append a chunk (OutputError when a file cannot take it: the partial files are removed)."""
        try:
            if self._csv_path:
                if self._csv is None:
                    self._csv = OutputFile(self._csv_path)
                self._csv.write(sweep_csv(res, motion, first_step=self.rows, header=self.rows == 0))
            if self._parquet_path:
                self._write_parquet(res, motion)
        except BaseException:  # a failed write or Ctrl-C: the partial files removed, the error goes on
            self.discard()
            raise
        self.rows += len(res.values)

    def _write_parquet(self, res, motion) -> None:
        import pyarrow as pa
        import pyarrow.parquet as pq

        head, cols = sweep_columns(res, motion)
        names = ["step"] + head
        arrays = [pa.array(np.arange(self.rows, self.rows + len(res.values), dtype=np.int64))]
        arrays += [pa.array(np.ascontiguousarray(c, dtype=float)) for c in cols]
        table = pa.Table.from_arrays(arrays, names=names)
        if self._pq is None:
            self._pq_file = OutputFile(self._parquet_path, "wb")
            self._pq = pq.ParquetWriter(self._pq_file, table.schema)
        self._pq.write_table(table)  # (a failed write of the file object is its OutputError)

    def close(self) -> None:
        """Finish both files: Parquet's footer written, each renamed to its name (OutputError when the
        last bytes cannot be written: the partial files are removed)."""
        try:
            if self._pq is not None:
                writer, self._pq = self._pq, None
                writer.close()
            for f in (self._pq_file, self._csv):
                if f is not None:
                    f.close()
            self._pq_file = self._csv = None
        except BaseException:  # a failed close or Ctrl-C: the partial files removed, the error goes on
            self.discard()
            raise

    def discard(self) -> None:
        """Stop writing and remove the partial files (the work failed or was interrupted, or a file could
        not be written): a sweep is never left under its name half written."""
        writer, self._pq = self._pq, None
        if writer is not None:
            try:
                writer.close()
            except Exception:  # noqa: BLE001, S110 - its file is discarded below
                pass
        for f in (self._csv, self._pq_file):
            if f is not None:
                f.discard()
        self._csv = self._pq_file = None
