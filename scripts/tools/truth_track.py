"""A simulator truth file (`truth.csv`) as a function of GPS time: shared by the scripts that
score a run against a moving truth."""
import bisect
import csv


class TruthTrack:
    """The ECEF positions of `truth.csv`, linearly interpolated in the time of week."""

    def __init__(self, path):
        self.rows = [(float(r["tow_s"]), float(r["x_m"]), float(r["y_m"]), float(r["z_m"]))
                     for r in csv.DictReader(open(path))]
        self.tows = [r[0] for r in self.rows]
        self.start_tow = self.tows[0]

    def at(self, tow):
        """The position at time of week `tow`, or None outside the file."""
        i = bisect.bisect_left(self.tows, tow)
        if i <= 0 or i >= len(self.tows):
            return None
        p, q = self.rows[i - 1], self.rows[i]
        f = (tow - p[0]) / (q[0] - p[0])
        return [p[k] + f * (q[k] - p[k]) for k in (1, 2, 3)]
