"""A paving as data: minimal-tree simplification, ``.npz`` storage and a separator on it
(thesis Remark 2.2, Eq. 2.59, §2.5.2, Algorithm 2.2).

A long computation's paving can be simplified, saved, loaded and reused as a separator:

>>> ring = SepInverse(Function(lambda x: (x[0] - 2) ** 2 + (x[1] - 2.5) ** 2), Interval(1, 2.25))
>>> p = pave(Box([(-1, 5), (-0.5, 5.5)]), ring, 0.05)
>>> s = SepSubpaving(simplify(p))
>>> xin, xout = s(Box([(3.1, 3.2), (2.4, 2.6)]))       # inside the ring
>>> bool(xin.is_empty().all())
True
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from digslam.observer.core.boxes import box_difference
from digslam.observer.core.types import Batch
from digslam.observer.paving.paver import Paving, PavingTree
from digslam.observer.sets.separators import Sep

_FIELDS = ("inner", "outer", "boundary")


def save(paving: Paving, path: str | Path) -> None:
    """Write a paving to ``.npz`` (plain arrays only; :func:`load` reads it without pickle)."""
    arrays = {f"{k}_{b}": getattr(paving, k)[i] for k in _FIELDS for i, b in enumerate(("lo", "hi"))}
    arrays |= {f"{k}_node": getattr(paving, f"{k}_node") for k in _FIELDS}
    t = paving.tree
    arrays |= {"tree_lo": t.lo, "tree_hi": t.hi, "tree_parent": t.parent, "tree_left": t.left}
    np.savez_compressed(path, bisections=paving.bisections, eps=paving.eps, **arrays)


def load(path: str | Path) -> Paving:
    """Read a paving written by :func:`save`, checking that every array is there and consistent."""
    with np.load(path, allow_pickle=False) as z:
        missing = {f"{k}_{s}" for k in _FIELDS for s in ("lo", "hi", "node")} - set(z.files)
        if missing:
            raise ValueError(f"{path}: not a digslam paving, missing arrays {sorted(missing)}")
        tree = PavingTree(z["tree_lo"], z["tree_hi"], z["tree_parent"], z["tree_left"])
        parts = {k: (z[f"{k}_lo"].astype(np.float64), z[f"{k}_hi"].astype(np.float64)) for k in _FIELDS}
        nodes = {k: z[f"{k}_node"].astype(np.int64) for k in _FIELDS}
        for k in _FIELDS:
            if parts[k][0].shape != parts[k][1].shape or len(nodes[k]) != len(parts[k][0]):
                raise ValueError(f"{path}: {k} boxes and nodes disagree in shape")
            if len(nodes[k]) and (nodes[k].min() < 0 or nodes[k].max() >= tree.size):
                raise ValueError(f"{path}: {k} boxes point to nodes outside the tree")
        return Paving(parts["inner"], parts["outer"], parts["boundary"], nodes["inner"], nodes["outer"],
                      nodes["boundary"], tree, int(z["bisections"]), float(z["eps"]))  # fmt: skip


def simplify(paving: Paving) -> Paving:
    """Merge sibling leaves wholly inside (or wholly outside) into their father (Eq. 2.59).

    A father whose two subtrees hold only inner boxes (and who stored no outer box itself) becomes a
    leaf holding one inner box, its own box; likewise for outer. The approximation is unchanged,
    the number of boxes drops. Runs level by level, bottom-up, vectorised over the tree.
    """
    t = paving.tree
    n = t.size
    has = {k: np.bincount(getattr(paving, f"{k}_node"), minlength=n) > 0 for k in _FIELDS}
    left = t.left.copy()
    pure = {"inner": ~has["outer"] & ~has["boundary"], "outer": ~has["inner"] & ~has["boundary"]}
    leaf_pure = {k: pure[k] & (left < 0) for k in pure}
    merged = np.zeros(n, dtype=bool)
    for _ in range(200):
        internal = np.flatnonzero(left >= 0)
        changed = False
        for k in pure:
            a, b = left[internal], left[internal] + 1
            ok = internal[pure[k][internal] & leaf_pure[k][a] & leaf_pure[k][b]]
            if ok.size:
                changed = True
                left[ok] = -1
                leaf_pure[k][ok] = True
                merged[ok] = True
        if not changed:
            break
    alive = _alive(t.parent, left)
    out = {}
    for k in _FIELDS:
        lo, hi = getattr(paving, k)
        node = getattr(paving, f"{k}_node")
        keep = alive[node] & ~merged[node]
        out[k] = ((lo[keep], hi[keep]), node[keep])
    for k in ("inner", "outer"):
        m = np.flatnonzero(merged & alive & leaf_pure[k])
        (lo, hi), node = out[k]
        out[k] = ((np.concatenate([lo, t.lo[m]]), np.concatenate([hi, t.hi[m]])), np.concatenate([node, m]))
    return Paving(
        out["inner"][0],
        out["outer"][0],
        out["boundary"][0],
        out["inner"][1],
        out["outer"][1],
        out["boundary"][1],
        PavingTree(t.lo, t.hi, t.parent, left),
        paving.bisections,
        paving.eps,
    )


def _alive(parent: np.ndarray, left: np.ndarray) -> np.ndarray:
    """Nodes still reachable from the root once some subtrees are cut (``left = -1``).

    Children are numbered after their parent, so a fixpoint over generations (depth passes) settles.
    """
    alive = np.ones(parent.size, dtype=bool)
    child = np.arange(1, parent.size)
    while True:
        p = parent[child]
        new = alive.copy()
        new[child] = alive[p] & (left[p] >= 0)
        if np.array_equal(new, alive):
            return alive
        alive = new


class SepSubpaving(Sep):
    """Separator for the set a paving describes (Algorithm 2.2), batched over query boxes.

    Query boxes walk down the bisection tree together (one vectorised step per level): a box meets
    the inner pieces (kept by ``x_out``), the outer pieces (kept by ``x_in``) and the boundary leaves
    (kept by both) of every node it overlaps. Parts of a query outside the initial box are unknown and
    kept by both.
    """

    def __init__(self, paving: Paving) -> None:
        self.p = paving
        self.n = paving.tree.lo.shape[1]
        self.index = {}
        for k in _FIELDS:
            node = getattr(paving, f"{k}_node")
            order = np.argsort(node, kind="stable")
            lo, hi = getattr(paving, k)
            start = np.searchsorted(node[order], np.arange(paving.tree.size))
            count = np.bincount(node, minlength=paving.tree.size)
            self.index[k] = (lo[order], hi[order], start, count)

    def separate(self, lo: np.ndarray, hi: np.ndarray) -> tuple[Batch, Batch]:
        t = self.p.tree
        xin = [np.full_like(lo, np.inf), np.full_like(hi, -np.inf)]
        xout = [np.full_like(lo, np.inf), np.full_like(hi, -np.inf)]
        root = (np.maximum(lo, t.lo[0]), np.minimum(hi, t.hi[0]))
        (plo, phi), rows = box_difference(lo, hi, *root)
        for acc in (xin, xout):
            _hull_at(acc, rows, plo, phi)
        q = np.arange(lo.shape[0])
        nd = np.zeros(lo.shape[0], dtype=np.int64)
        while q.size:
            ilo, ihi = np.maximum(lo[q], t.lo[nd]), np.minimum(hi[q], t.hi[nd])
            meet = (ilo <= ihi).all(axis=1)
            q, nd, ilo, ihi = q[meet], nd[meet], ilo[meet], ihi[meet]
            for k, targets in (("inner", (xout,)), ("outer", (xin,)), ("boundary", (xin, xout))):
                b_lo, b_hi, start, count = self.index[k]
                c = count[nd]
                rep = np.repeat(np.arange(q.size), c)
                pid = start[nd][rep] + np.arange(rep.size) - np.repeat(np.cumsum(c) - c, c)
                s_lo, s_hi = np.maximum(ilo[rep], b_lo[pid]), np.minimum(ihi[rep], b_hi[pid])
                ok = (s_lo <= s_hi).all(axis=1)
                for acc in targets:
                    _hull_at(acc, q[rep][ok], s_lo[ok], s_hi[ok])
            down = t.left[nd] >= 0
            q = np.concatenate([q[down], q[down]])
            nd = np.concatenate([t.left[nd[down]], t.left[nd[down]] + 1])
        return (xin[0], xin[1]), (xout[0], xout[1])


def _hull_at(acc: list[np.ndarray], rows: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> None:
    np.minimum.at(acc[0], rows, lo)
    np.maximum.at(acc[1], rows, hi)


__all__ = [
    "SepSubpaving",
    "load",
    "save",
    "simplify",
]
