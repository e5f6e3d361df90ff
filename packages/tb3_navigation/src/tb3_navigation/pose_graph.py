"""A 2-D pose graph: poses (x, y, yaw) tied by relative-pose constraints, optimised by sparse
Gauss-Newton (scipy), the back end Karto and slam_toolbox give their scan matchers. No ROS here.

A constraint (i, j, z, information) says that pose j seen from pose i is z (x, y, yaw in i's
frame), with an information matrix (the inverse covariance) on z's three values in that frame.
Its error is relative(x_i, x_j) - z, the angle wrapped; optimising minimises the sum of the
errors' squares weighted by their information, pose 0 held where it is (the map's origin).
"""
import numpy as np
from scipy import sparse
from scipy.sparse import linalg

from tb3_common.pose2d import normalize_angle


class PoseGraph(object):

    def __init__(self):
        self.poses = np.zeros((0, 3))
        self._from, self._to = [], []
        self._measured, self._information = [], []

    def __len__(self):
        return len(self.poses)

    @property
    def edges(self):
        return len(self._from)

    def add_pose(self, pose):
        """Adds a pose (x, y, yaw); returns its index."""
        self.poses = np.vstack((self.poses, np.asarray(pose, dtype=float)[None, :3]))
        return len(self.poses) - 1

    def add_edge(self, i, j, measured, information):
        """Pose j seen from pose i is `measured` (x, y, yaw), with `information` (3, 3)."""
        self._from.append(i)
        self._to.append(j)
        self._measured.append(np.asarray(measured, dtype=float))
        self._information.append(np.asarray(information, dtype=float))

    def errors(self, poses=None):
        """(m, 3): each constraint's error at `poses` (default: the graph's)."""
        poses = self.poses if poses is None else poses
        i, j = np.array(self._from, dtype=np.intp), np.array(self._to, dtype=np.intp)
        return self._errors(poses, i, j, np.array(self._measured).reshape(-1, 3))[0]

    @staticmethod
    def _errors(poses, i, j, measured):
        cos, sin = np.cos(poses[i, 2]), np.sin(poses[i, 2])
        dx, dy = poses[j, 0] - poses[i, 0], poses[j, 1] - poses[i, 1]
        error = np.stack((cos * dx + sin * dy - measured[:, 0], -sin * dx + cos * dy - measured[:, 1],
                          normalize_angle(poses[j, 2] - poses[i, 2] - measured[:, 2])), axis=-1)
        return error, cos, sin, dx, dy

    def cost(self, poses=None):
        """The weighted sum of the errors' squares."""
        error = self.errors(poses)
        return float(np.einsum('mi,mij,mj->', error, np.array(self._information).reshape(-1, 3, 3), error))

    def optimize(self, iterations=20, tolerance=1e-6):
        """Gauss-Newton until no pose moves more than `tolerance` (m, rad) or `iterations`; pose 0 stays.
        Returns how far the poses moved at most (m or rad)."""
        n = len(self.poses)
        if n < 2 or not self._from:
            return 0.0
        i, j = np.array(self._from, dtype=np.intp), np.array(self._to, dtype=np.intp)
        measured = np.array(self._measured)
        information = np.array(self._information)
        start = self.poses.copy()
        poses = start.copy()
        m = len(i)
        for _ in range(iterations):
            error, cos, sin, dx, dy = self._errors(poses, i, j, measured)
            # d(error)/d(pose i) and d(error)/d(pose j), (m, 3, 3).
            a = np.zeros((m, 3, 3))
            a[:, 0, 0], a[:, 0, 1], a[:, 0, 2] = -cos, -sin, -sin * dx + cos * dy
            a[:, 1, 0], a[:, 1, 1], a[:, 1, 2] = sin, -cos, -cos * dx - sin * dy
            a[:, 2, 2] = -1.0
            b = np.zeros((m, 3, 3))
            b[:, 0, 0], b[:, 0, 1], b[:, 1, 0], b[:, 1, 1], b[:, 2, 2] = cos, sin, -sin, cos, 1.0
            at_omega, bt_omega = np.einsum('mki,mkl->mil', a, information), np.einsum('mki,mkl->mil', b, information)
            blocks = (np.einsum('mil,mlj->mij', at_omega, a), np.einsum('mil,mlj->mij', at_omega, b),
                      np.einsum('mil,mlj->mij', bt_omega, a), np.einsum('mil,mlj->mij', bt_omega, b))
            rows, cols, values = [], [], []
            for block, (first, second) in zip(blocks, ((i, i), (i, j), (j, i), (j, j))):
                rows.append((3 * first[:, None, None] + np.arange(3)[None, :, None]).repeat(3, axis=2).ravel())
                cols.append((3 * second[:, None, None] + np.arange(3)[None, None, :]).repeat(3, axis=1).ravel())
                values.append(block.ravel())
            # Pose 0 held: its rows and columns become the identity's.
            rows, cols, values = np.concatenate(rows), np.concatenate(cols), np.concatenate(values)
            free = (rows >= 3) & (cols >= 3)
            hessian = sparse.coo_matrix((np.concatenate((values[free], np.ones(3))),
                                         (np.concatenate((rows[free], np.arange(3))),
                                          np.concatenate((cols[free], np.arange(3))))), shape=(3 * n, 3 * n)).tocsc()
            gradient = np.zeros(3 * n)
            for poses_of, weighted in ((i, at_omega), (j, bt_omega)):
                np.add.at(gradient, (3 * poses_of[:, None] + np.arange(3)).ravel(),
                          np.einsum('mil,ml->mi', weighted, error).ravel())
            gradient[:3] = 0.0
            step = linalg.spsolve(hessian, -gradient).reshape(n, 3)
            poses += step
            poses[:, 2] = normalize_angle(poses[:, 2])
            if np.abs(step).max() < tolerance:
                break
        moved = poses - start
        moved[:, 2] = normalize_angle(moved[:, 2])
        self.poses = poses
        return float(np.abs(moved).max())
