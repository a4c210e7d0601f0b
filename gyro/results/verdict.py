"""One verdict type for every stability answer of the project: a label per set and, where
the label is not plainly 'stable' or 'unstable', one line saying why.

The labels:

- ``stable``: certain within the stated bounds (every root simple on the imaginary axis of
  a conservative system, or a sufficient condition whose margins all exceed their rounding
  bounds);
- ``marginal``: a neutral direction found exactly (an exact zero root: a free coordinate);
- ``unstable``: a root grows by more than its error bound;
- ``boundary``: rounding could change the verdict (roots merged within their error bounds
  in a cluster that may reach the imaginary axis: cluster_meets_axis; a root not resolved
  from zero; a condition's margin within its rounding bound of zero);
  never counted as stable or as stabilised;
- ``unknown``: no bound (a method that lost a root, or computes no growth rates);
- ``failed``: the set could not be computed.

Two tests do the work, and every analysis reads its verdicts through them:
`condition` (the margins of a sufficient condition against their rounding bounds) and
`spectrum` (eigenvalues with error radii: disks that contain the exact roots). Why the
tests decide what they claim, and where the bounds come from: docs/gyrohorizoncompass.md,
section "Boundaries: verdicts that rounding could change".
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from gyro.results._io import Result

LABELS = ("stable", "marginal", "unstable", "boundary", "unknown", "failed")
EPS = float(np.finfo(float).eps)  # 2 u: the spacing of doubles at 1
UNIT_ROUNDOFF = EPS / 2  # u


@dataclass
class Verdict(Result):
    """Per set of a batch: its label (one of LABELS) and a reason (None, or one line)."""

    label: np.ndarray  # (sets,) object: str
    reason: np.ndarray  # (sets,) object: str or None

    NO_PLOT = "a label per set: the figure of what holds it draws it (a map, a Campbell diagram)"

    def to_dict(self) -> dict:
        """Per set: `verdict` (the label) and `reason` (null, or one line)."""
        return {"verdict": [str(v) for v in self.label], "reason": [None if r is None else str(r) for r in self.reason]}

    def table(self) -> str:
        """A line per set: its label, and its reason where it has one."""
        return "\n".join(f"{k + 1:>4}  {v}" + (f" ({r})" if r else "") for k, (v, r) in
                         enumerate(zip(self.label, self.reason)))

    @classmethod
    def _loaded(cls, v) -> "Verdict":
        return make(v.label, v.reason)

    def __len__(self) -> int:
        return len(self.label)

    @property
    def boundary(self) -> np.ndarray:
        return np.asarray(self.label == "boundary", bool)

    def counts(self) -> dict:
        """{label: number of sets} for the labels present (in the order of LABELS)."""
        return {k: int(np.sum(self.label == k)) for k in LABELS if np.any(self.label == k)}


def make(label, reason=None) -> Verdict:
    """A Verdict from arrays (or one label and reason)."""
    label = np.atleast_1d(np.asarray(label, dtype=object))
    bad = set(label) - set(LABELS)
    if bad:
        raise ValueError(f"not a verdict: {sorted(bad)}")
    reason = np.full(label.shape, None, dtype=object) if reason is None else \
        np.broadcast_to(np.asarray(reason, dtype=object), label.shape).copy()
    return Verdict(label, reason)


def condition(margin: np.ndarray, bound: np.ndarray, names) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A sufficient condition 'every margin > 0' over a batch: margins (sets, k) with their
    rounding bounds (sets, k) (|computed - exact| <= bound), names (k,).

    Returns (holds, decided, reason): `holds` where every margin exceeds its bound (the
    exact margins are all positive), `decided` where it holds or some margin lies below
    minus its bound (one exact margin is negative, so the condition fails whatever the
    others are); elsewhere rounding could change the answer, and `reason` names the first
    margin within its bound of zero."""
    margin, bound = np.atleast_2d(margin), np.atleast_2d(bound)
    ok = np.isfinite(margin) & np.isfinite(bound)
    above = ok & (margin > bound)
    below = ok & (margin < -bound)
    holds = np.all(above, axis=1)
    decided = holds | np.any(below, axis=1)
    reason = np.full(margin.shape[0], None, dtype=object)
    for k in np.flatnonzero(~decided):
        j = int(np.argmax(~above[k] & ~below[k]))
        reason[k] = (f"the margin {names[j]} = {margin[k, j]:.3g} lies within its rounding bound "
                     f"{bound[k, j]:.2g} of zero")
    return holds, decided, reason


def overlapping(lam: np.ndarray, radius: np.ndarray) -> np.ndarray:
    """(sets, m, m): the disks |z - lam_i| <= radius_i and |z - lam_j| <= radius_j meet
    (i != j): the exact roots there may coincide."""
    d = np.abs(lam[:, :, None] - lam[:, None, :])
    return (d <= radius[:, :, None] + radius[:, None, :]) & ~np.eye(lam.shape[1], dtype=bool)


def cluster_meets_axis(lam: np.ndarray, radius: np.ndarray, rel: np.ndarray) -> np.ndarray:
    """(sets, m): root i belongs to a cluster (roots whose disks |z - lam| <= radius overlap,
    joined transitively) that may reach the imaginary axis, where a collision can change a
    verdict. A single root's bound does not hold inside a cluster: a c-fold root of a
    problem perturbed by a relative delta moves by up to |lambda| delta^(1/c) (the Puiseux
    expansion of a c-fold root; a Jordan block attains it), so the cluster's roots are known
    only to R = 2 max |lambda| max(rel)^(1/c), rel the members' relative error bounds (each
    at least the backward error it rests on). A cluster all of whose roots lie farther than
    R from the axis keeps every root on its side whatever rounding did: a double root well
    inside the left half-plane (a damped isotropic rotor at rest: Re <= -12.7 1/s, R about
    1e-15 1/s) cannot change the verdict. Roots in no cluster: True (their own disks
    decide)."""
    lam, radius, rel = np.atleast_2d(lam), np.atleast_2d(radius), np.atleast_2d(rel)
    ov = overlapping(lam, radius)
    out = np.ones(lam.shape, bool)
    for k in np.flatnonzero(ov.any(axis=(1, 2))):
        seen = np.zeros(lam.shape[1], bool)
        for i in np.flatnonzero(ov[k].any(axis=1)):
            if seen[i]:
                continue
            members, todo = {int(i)}, [int(i)]
            while todo:
                new = set(np.flatnonzero(ov[k, todo.pop()]).tolist()) - members
                members |= new
                todo += list(new)
            c = np.array(sorted(members))
            seen[c] = True
            with np.errstate(all="ignore"):
                R = 2 * np.max(np.abs(lam[k, c])) * np.max(np.abs(rel[k, c])) ** (1.0 / len(c))
            out[k, c] = not np.all(np.abs(lam[k, c].real) > R)  # NaN: it may
    return out


def spectrum(lam: np.ndarray, radius: np.ndarray, conservative: bool = True,
             exact_zero: np.ndarray | None = None) -> Verdict:
    """Verdicts from eigenvalues lam (sets, m) and error radii (sets, m): the exact roots
    lie in the disks |z - lam| <= radius (radius inf or NaN: unbounded; lam not finite:
    failed).

    - unstable: some disk lies in Re z > 0 (a root grows whatever rounding did); when
      `conservative`, also a disk wholly in Re z < 0 (its mirror root grows);
    - boundary: otherwise, when `conservative`, two disks overlap or a root's mirror disk
      meets another root's disk (the exact roots may coincide there: a Krein collision, a
      Jordan block, a zero root with its mirror image);
    - stable: otherwise, when `conservative` (a Hamiltonian spectrum: an isolated disk that
      meets the axis holds one root, and its mirror image -conj(z), which must lie in the
      same disk, is the root itself: it is on the axis); without `conservative` every
      disk must lie in Re z < 0, a disk that meets the axis being a boundary.

    `exact_zero` (sets,) int: the number of free coordinates, each with an exact double
    zero root (known from the structure, not from rounding). Their 2 per coordinate roots
    of least modulus are set aside (their disks say nothing: a Jordan block's radius is
    huge), and the rest decides: a set that would be stable is marginal."""
    lam, radius = np.atleast_2d(lam), np.atleast_2d(radius)
    n, m = lam.shape
    if exact_zero is not None and np.any(exact_zero):
        zeros = 2 * np.asarray(exact_zero, int)
        order = np.argsort(np.where(np.isfinite(lam), np.abs(lam), np.inf), axis=1)
        aside = np.zeros(lam.shape, bool)
        for k in np.flatnonzero(zeros):
            aside[k, order[k, :zeros[k]]] = True
        # set aside: moved far apart from each other and the rest, with no radius
        far = np.where(aside, 1e300 * (1 + np.arange(m))[None, :] * 1j, lam)
        v = spectrum(far, np.where(aside, 0.0, radius), conservative)
        marg = np.asarray(zeros > 0) & (v.label == "stable")
        v.label[marg] = "marginal"
        v.reason[marg] = "an exact zero root (a free coordinate): the linearisation decides nothing"
        return v
    failed = ~np.all(np.isfinite(lam), axis=1)
    unbounded = ~np.all(np.isfinite(radius), axis=1) & ~failed
    r = np.where(np.isfinite(radius), radius, np.inf)
    # a conservative (Hamiltonian) spectrum is symmetric about the axis: a disk off the
    # axis on either side proves a growing root
    grows = np.any((np.abs(lam.real) if conservative else lam.real) > r, axis=1) & ~failed
    overlap = overlapping(lam, r)
    if conservative:  # the argument for 'stable' needs each root's mirror disk to meet no other disk
        d = np.abs(-np.conj(lam)[:, :, None] - lam[:, None, :])
        overlap |= (d <= r[:, :, None] + r[:, None, :]) & ~np.eye(m, dtype=bool)
    at_zero = np.abs(lam) <= r
    # without `conservative` the disks decide alone: a union of disks in Re z < 0 holds only
    # roots there (the disks are rigorous, merged or not), one that meets the axis is on_axis
    merged = np.any(overlap, axis=(1, 2)) if conservative else np.zeros(n, bool)
    on_axis = np.any(np.abs(lam.real) <= r, axis=1)
    label = np.full(n, "stable", dtype=object)
    reason = np.full(n, None, dtype=object)
    label[grows] = "unstable"
    for k in np.flatnonzero(failed | (~grows & (unbounded | merged | (not conservative) & on_axis))):
        if failed[k]:
            label[k], reason[k] = "failed", "a root could not be computed"
        elif grows[k]:
            label[k] = "unstable"
        elif unbounded[k]:
            label[k], reason[k] = "unknown", "a root's error is unbounded"
        elif merged[k]:
            i, j = np.argwhere(overlap[k])[0]
            if at_zero[k, i] and at_zero[k, j]:
                label[k] = "boundary"
                reason[k] = (f"a zero root: roots {lam[k, i]:.3g} and {lam[k, j]:.3g} lie within their error "
                             f"bounds ({r[k, i]:.2g}) of zero and of each other")
            else:
                label[k] = "boundary"
                reason[k] = (f"roots {lam[k, i]:.6g} and {lam[k, j]:.6g} merge within their error bounds "
                             f"({r[k, i]:.2g}, {r[k, j]:.2g}): a possible collision")
        elif not conservative and on_axis[k]:
            label[k], reason[k] = "boundary", "a root's real part lies within its error bound of zero"
    return Verdict(label, reason)
