"""Throughput of the screening on the paper's candidate grid, with random-weight networks.

    python -m tests.screening_bench [--hidden 15] [--threads 2] [--sequential] [--chunk N]

Four random-weight tanh networks of the size of the trained surrogates stand for mu_psh, mu_sh,
rho_b (7 inputs) and the angle of repose (5 inputs), so the cost per set equals that of real
networks. The grid is ``screening.axes`` of ``config/paper.yaml`` (paper Table 3, 6.25 M sets).
The stand-in networks are also the test surrogates of ``tests/unit/test_screening.py``.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Mapping
from pathlib import Path

import numpy as np
import torch

from demcal.core.config import load_config
from demcal.core.experiments import MeasuredCondition
from demcal.identification.candidate_grid import DEFAULT_CHUNK_SIZE, draw_axes
from demcal.identification.screening import ScreeningResult, screen
from demcal.identification.screening_stages import PredictorEntry, Stage

ROOT = Path(__file__).resolve().parents[1]

SHEAR_FEATURES = (
    "coefficientFriction",
    "coefficientRollingFriction",
    "coefficientRestitution",
    "density",
    "dCylDp",
    "normal_stress",
    "P",
)
"""Input features of the shear-cell networks, in order."""

REPOSE_FEATURES = SHEAR_FEATURES[:5]
"""Input features of the angle-of-repose network, in order."""

# Input standardisation of the stand-ins (SI units of SHEAR_FEATURES), about the spread of the
# paper's design, and the output scale of each bulk value.
IN_MEAN = np.array([0.55, 0.55, 0.7, 3000.0, 20.0, 5000.0, 0.7])
IN_SCALE = np.array([0.26, 0.26, 0.12, 290.0, 5.0, 4000.0, 0.2])
OUTPUTS = {"mu_psh": (0.6, 0.1), "mu_sh": (0.5, 0.1), "rho_b": (1700.0, 100.0)}
AOR_OUTPUT = (35.0, 5.0)
FIXED = {"dCylDp": 20.0, "normal_stress": 10070.0, "P": 1.0}


class RandomTanhNetwork:
    """Stand-in surrogate with random weights: one tanh hidden layer, one linear output.

    Inputs are standardised with the given means and scales and the output is mapped to
    ``out_mean + out_scale * y``, as a trained surrogate would do.

    Parameters
    ----------
    n_features : int
        Number of inputs d.
    n_hidden : int
        Number of tanh units.
    seed : int
        Seed of the weights.
    in_mean, in_scale : array_like, shape (d,)
        Input standardisation (SI units of each feature).
    out_mean, out_scale : float
        Output mapping, in the units of the predicted bulk value.
    """

    def __init__(
        self,
        n_features: int,
        n_hidden: int,
        seed: int,
        in_mean: np.ndarray,
        in_scale: np.ndarray,
        out_mean: float,
        out_scale: float,
    ) -> None:
        gen = torch.Generator().manual_seed(seed)
        self.w1 = torch.randn(n_features, n_hidden, generator=gen) / math.sqrt(n_features)
        self.b1 = 0.1 * torch.randn(n_hidden, generator=gen)
        self.w2 = torch.randn(n_hidden, 1, generator=gen) / math.sqrt(n_hidden)
        self.b2 = float(0.1 * torch.randn(1, generator=gen))
        self.in_mean = torch.as_tensor(np.asarray(in_mean, dtype=np.float32))
        self.in_scale = torch.as_tensor(np.asarray(in_scale, dtype=np.float32))
        self.out_mean = float(out_mean)
        self.out_scale = float(out_scale)

    def predict_torch(self, X: torch.Tensor) -> torch.Tensor:
        """Predictions, float32 tensor of shape (n,), for inputs of shape (n, d)."""
        with torch.no_grad():
            Z = (X - self.in_mean) / self.in_scale
            H = torch.tanh(torch.addmm(self.b1, Z, self.w1))
            y = torch.addmm(torch.tensor([self.b2]), H, self.w2).reshape(-1)
            return y.mul_(self.out_scale).add_(self.out_mean)

    def predict(self, X: np.ndarray) -> np.ndarray:
        """Predictions, float64 array of shape (n,), for inputs of shape (n, d)."""
        X32 = torch.from_numpy(np.asarray(X, dtype=np.float32))
        return self.predict_torch(X32).numpy().astype(np.float64)


def paper_axes_spec() -> dict[str, tuple[float, float, int]]:
    """``screening.axes`` of ``config/paper.yaml``: per parameter (low, high, count)."""
    axes = load_config(ROOT / "config" / "paper.yaml")["screening"]["axes"]
    return {name: (float(lo), float(hi), int(n)) for name, (lo, hi, n) in axes.items()}


def stand_in_networks(n_hidden: int = 15, seed: int = 0) -> dict[str, PredictorEntry]:
    """The four stand-in surrogates with their input features, by output name."""
    predictors: dict[str, PredictorEntry] = {}
    for k, (name, (mean, scale)) in enumerate(OUTPUTS.items()):
        net = RandomTanhNetwork(7, n_hidden, seed + k, IN_MEAN, IN_SCALE, mean, scale)
        predictors[name] = (net, SHEAR_FEATURES)
    aor = RandomTanhNetwork(5, n_hidden, seed + 3, IN_MEAN[:5], IN_SCALE[:5], *AOR_OUTPUT)
    predictors["aor"] = (aor, REPOSE_FEATURES)
    return predictors


def screen_stand_ins(
    spec: Mapping[str, tuple[float, float, int]],
    n_hidden: int = 15,
    seed: int = 0,
    chunk_size: int = DEFAULT_CHUNK_SIZE,
    num_threads: int = 2,
    sequential: bool = False,
) -> ScreeningResult:
    """Screen the grid of ``spec`` with the stand-in networks.

    The measured values are the networks' predictions at the middle of the grid with 5 %
    tolerance. With ``sequential=False`` all four networks run on every set (one stage, the
    worst case); with ``sequential=True`` the repose network runs only on the sets the shear
    networks marked (eq. 3 then eq. 4).
    """
    axes = draw_axes(spec, seed)
    predictors = stand_in_networks(n_hidden, seed)
    centre = {name: float(np.median(values)) for name, values in axes.items()}
    measured: dict[str, float] = {}
    for name, (model, features) in predictors.items():
        row = np.array([[centre.get(f, FIXED.get(f, 0.0)) for f in features]])
        measured[name] = float(model.predict(row)[0])
    load = {"normal_stress": FIXED["normal_stress"], "P": FIXED["P"]}
    if sequential:
        shear = {k: measured[k] for k in OUTPUTS}
        stages: list[Stage | MeasuredCondition] = [
            MeasuredCondition(shear, **load),
            MeasuredCondition({"aor": measured["aor"]}),
        ]
    else:
        stages = [MeasuredCondition(measured, **load, name="all")]
    fixed = {"dCylDp": FIXED["dCylDp"]}
    return screen(predictors, axes, fixed, stages, chunk_size=chunk_size, num_threads=num_threads)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--hidden", type=int, default=15, help="tanh units per network")
    parser.add_argument("--threads", type=int, default=2, help="torch threads")
    parser.add_argument("--chunk", type=int, default=DEFAULT_CHUNK_SIZE, help="sets per chunk")
    parser.add_argument(
        "--sequential", action="store_true", help="repose network only on marked sets"
    )
    args = parser.parse_args()
    result = screen_stand_ins(
        paper_axes_spec(),
        n_hidden=args.hidden,
        chunk_size=args.chunk,
        num_threads=args.threads,
        sequential=args.sequential,
    )
    mode = "sequential" if args.sequential else "all four networks on every set"
    print(
        f"screening ({mode}, {args.hidden} hidden, {args.threads} threads): "
        f"{result.n_total} sets in {result.elapsed_s:.2f} s = "
        f"{result.sets_per_second:.3g} sets/s, {result.n_accepted} accepted"
    )


if __name__ == "__main__":
    main()
