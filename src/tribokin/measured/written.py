"""What the results of measured data share: a table (``rows()``: ``poses.csv``, ``comparison.csv``) as a pandas
DataFrame, and the command's folder written by :func:`tribokin.output.dispatch.write_folder` (through the writer
:mod:`tribokin.output.measured` registers for the result's type)."""

from __future__ import annotations

from pathlib import Path

from tribokin.output.dispatch import write_folder


class Written:
    """A result whose command writes a folder with a table; the subclass gives the table's rows (``rows()``)."""

    def to_pandas(self):
        """The table (``rows()``) as a pandas DataFrame: the same columns and numbers as its CSV file (units in the
        names), NaN where the file's cell is empty (pandas: ``pip install 'tribokin[data]'``)."""
        from tribokin.simulation.pose_result import pose_frame

        return pose_frame(self.rows(), [])

    def write(self, folder, force: bool = False, *, report: str = "full") -> Path:
        """Write the files the command writes into ``folder`` (``report``: ``"full"`` writes ``report.html``,
        ``"none"`` does not): all at once, its lock held, refused (:class:`~tribokin.errors.InputError`) if it
        exists, unless ``force``.

        Returns:
            the folder written.
        """
        return write_folder(self, folder, force, report=report)  # output.measured: write_measurement, write_calibration
