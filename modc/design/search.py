"""The twist search for one shape: which pivot and port settings let the arm do every task.

Small spaces are enumerated exhaustively. Larger ones are searched with CMA-ES (the `cma`
package) over the twist indices: the screen's score (how far the closest IK runs end from their
targets, plus a penalty per target reached only in collision) is smooth enough in the twist
angles for a covariance-adapting search to descend it, CMA-ES needs no gradient and no tuning
beyond a budget, and with its seed fixed it is deterministic. (pymoo/optuna would add a
dependency for the same single-objective, small-dimensional problem: the ranking objectives
are handled exactly by the enumeration of shapes, not by the optimiser.)

Everything here is a function of (spec, shape, seed): the same inputs give the same answer in any
process, which makes the result independent of the number of workers.
"""
from __future__ import annotations

import itertools
import zlib
from dataclasses import dataclass

import numpy as np

from .evaluate import Spec, screen_batch
from .space import Shape, port_free, twist_values

EXHAUSTIVE = 1536  # twist settings enumerated outright up to this many
BUDGET = 1024  # CMA-ES evaluations per shape beyond that
BATCH = 512  # candidates screened together (numpy amortisation)
KEEP = 6  # feasible twist settings kept per shape (simplest first)


@dataclass(frozen=True)
class Found:
    pivots: tuple[float, ...]
    ports: tuple[float, ...]
    solutions: tuple[tuple[tuple[float, ...], ...], ...]  # per target, joint vectors passing the screen


@dataclass(frozen=True)
class ShapeResult:
    shape: Shape
    found: tuple[Found, ...]
    evaluated: int
    closest: tuple[float, ...]  # per target: the smallest position error any setting reached, m
    best_score: float


def shape_seed(seed: int, shape: Shape) -> int:
    return zlib.crc32(f"{seed}:{shape.label()}".encode()) & 0x7FFFFFFF


def _complexity(pivots, ports) -> tuple:
    """Simplest first: fewest twists set, then the smallest angles, then the values."""
    vals = np.concatenate([pivots, ports])
    return (int(np.count_nonzero(np.abs(vals) > 1e-9)), round(float(np.abs(vals).sum()), 9),
            tuple(round(float(v), 9) for v in vals))


class _Tally:
    def __init__(self, T: int):
        self.found: dict[tuple, Found] = {}
        self.evaluated = 0
        self.closest = np.full(T, np.inf)
        self.best = np.inf

    def add(self, spec: Spec, shape: Shape, piv: np.ndarray, por: np.ndarray, seed: int) -> np.ndarray:
        s = screen_batch(spec, shape, piv, por, seed)
        self.evaluated += len(piv)
        self.closest = np.minimum(self.closest, s.closest.min(0))  # inf where no candidate got that far
        self.best = min(self.best, float(s.score.min()))
        for k, c in enumerate(np.flatnonzero(s.feasible)):
            key = (tuple(float(x) for x in piv[c]), tuple(float(x) for x in por[c]))
            if key not in self.found:
                sols = tuple(tuple(tuple(float(x) for x in q) for q in per) for per in s.solutions[k])
                self.found[key] = Found(key[0], key[1], sols)
        return s.score

    def result(self, shape: Shape) -> ShapeResult:
        found = sorted(self.found.values(), key=lambda f: _complexity(np.array(f.pivots), np.array(f.ports)))
        return ShapeResult(shape, tuple(found[:KEEP]), self.evaluated, tuple(float(x) for x in self.closest), self.best)


def search_shape(spec: Spec, shape: Shape, seed: int) -> ShapeResult:
    lib = spec.problem.cell.library
    assert lib is not None
    pivot_set, port_set = twist_values(lib.twists.pivot), twist_values(lib.twists.port)
    free = port_free(spec.problem, shape, lib)
    # one variable per pivot and per port that matters
    axes = [pivot_set] * shape.n + [port_set for f in free if f]
    where = [i for i, f in enumerate(free) if f]
    n = shape.n
    tally = _Tally(len(spec.targets.names))
    s0 = shape_seed(seed, shape)

    def split(values: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        piv = values[:, :n]
        por = np.zeros((len(values), n))
        por[:, where] = values[:, n:]
        return piv, por

    size = int(np.prod([len(a) for a in axes]))
    if size <= EXHAUSTIVE:
        grid = np.array(list(itertools.product(*axes)), float).reshape(-1, len(axes))
        for lo in range(0, len(grid), BATCH):
            tally.add(spec, shape, *split(grid[lo:lo + BATCH]), s0)
        return tally.result(shape)

    import warnings

    with warnings.catch_warnings():  # cma warns that matplotlib (for its plots) is missing
        warnings.simplefilter("ignore")
        import cma

    dims = np.array([len(a) for a in axes], float)
    # CMA-ES draws from its own generator: numpy's global one is shared by the threads of a Dask
    # worker, and drawing from it would make results depend on how shapes interleave
    rng = np.random.default_rng(s0)
    x0 = np.array([float(np.argmin(np.abs(a))) + 0.5 for a in axes])  # every twist at 0
    opts = {"bounds": [np.zeros_like(dims).tolist(), (dims - 1e-9).tolist()], "verbose": -9,
            "popsize": 64, "maxfevals": BUDGET, "CMA_stds": (dims / 4).tolist(), "tolfun": 0, "tolx": 1e-3,
            "randn": lambda *shape: rng.standard_normal(shape)}
    es = cma.CMAEvolutionStrategy(x0.tolist(), 1.0, opts)
    while not es.stop() and tally.evaluated < BUDGET and len(tally.found) < KEEP * 2:
        xs = es.ask()
        idx = np.clip(np.floor(np.array(xs)), 0, dims - 1).astype(int)
        values = np.array([[axes[j][i] for j, i in enumerate(row)] for row in idx])
        scores = tally.add(spec, shape, *split(values), s0)
        es.tell(xs, (scores + 1e-6 * np.abs(values).sum(1)).tolist())
    return tally.result(shape)


def search_chunk(spec: Spec, shapes: list[Shape], seed: int) -> list[ShapeResult]:
    """A worker's unit of work: several shapes, searched one after the other."""
    return [search_shape(spec, s, seed) for s in shapes]
