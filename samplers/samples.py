"""The sample arrays of a scan, edited in place by the layouts and repairs."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .repair import Repaired


@dataclass
class Samples:
    """The sample arrays of :func:`sr33.samplers.scanline.scan`, edited in place by the repairs."""

    points: np.ndarray
    line_id: np.ndarray
    face_id: np.ndarray
    on_feature: np.ndarray

    def replace(self, drop: np.ndarray, points, line_id, face_id, on_feature) -> None:
        keep = np.ones(self.points.shape[0], dtype=bool)
        keep[drop] = False
        self.points = np.vstack([self.points[keep], points])
        self.line_id = np.r_[self.line_id[keep], line_id].astype(np.int64)
        self.face_id = np.r_[self.face_id[keep], face_id].astype(np.int64)
        self.on_feature = np.r_[self.on_feature[keep], on_feature].astype(bool)

    def put(self, idx: np.ndarray, r: Repaired, points: np.ndarray, face: int, kind: str) -> dict:
        """Replace the samples ``idx`` by the answer ``r`` of their repair
        (its samples at ``points``, in 3-D): a sample it kept keeps its
        line, face and feature flag; one it added is on line -3, on
        ``face``, off the features.  Returns the face's report."""
        src = np.where(r.origin >= 0, idx[np.maximum(r.origin, 0)], -1)
        moved = src >= 0
        was = np.maximum(src, 0)
        self.replace(
            idx,
            points,
            np.where(moved, self.line_id[was], -3),
            np.where(moved, self.face_id[was], face),
            np.where(moved, self.on_feature[was], False),
        )
        return {
            "face": face,
            "kind": kind,
            "samples": int(idx.size),
            "added": int((~moved).sum()),
            "removed": int(idx.size - moved.sum()),
            "bad": r.bad,
            "worst": r.worst,
        }
