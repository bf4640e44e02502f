"""The decks the fuzzer mutates: the tiny profile's shear cell (split and ring), angle of
repose and chute cooler."""

from __future__ import annotations

from pathlib import Path

from demcal.application.chute_cooler.deck import DECK_NAME as CHUTE_DECK
from demcal.application.chute_cooler.deck import render_chute_cooler
from demcal.core.config import load_config
from demcal.robustness.mutation import BaseDeck
from demcal.virtual_tests.deck import DECK_NAMES, render_case

#: The shear-cell keys that make the quick profile's ring cell (its geometry and width in mean
#: radii, its cycle mode and where it measures rho_b); with the tiny particles the ring is the
#: same number of particles wide.
RING_KEYS = (
    "geometry",
    "dCylDp",
    "overfill",
    "cycles",
    "bulk_density",
    "interior_margin",
)

#: Bed height of that ring over its outer radius: 6 mean diameters, the quick bed until
#: 2026-12-07 (9 since), at which the tests' expectations and the comparisons with LIGGGHTS 3.8
#: were measured; two thirds of the particles keep the test and fuzzer runs short.
RING_FILL_HEIGHT = 0.5


def with_quick_ring(config: Path, keys: tuple[str, ...] = RING_KEYS) -> dict:
    """A validated configuration whose shear cell is the ring of ``config/config.yaml``, with a
    bed :data:`RING_FILL_HEIGHT` high.

    Parameters
    ----------
    config : Path
        Configuration file (the tiny profile in the tests and the fuzzer).
    keys : tuple of str
        Shear-cell keys taken from the quick profile.

    Returns
    -------
    dict
        ``config`` validated, with ``keys`` of the quick profile's shear cell.
    """
    root = Path(__file__).resolve().parents[2]
    quick = load_config(root / "config" / "config.yaml")["shear_cell"]
    cfg = load_config(config)
    cfg["shear_cell"].update({key: quick[key] for key in keys}, fill_height=RING_FILL_HEIGHT)
    return cfg


def render_base_decks(work_dir: Path, config: Path | None = None) -> list[BaseDeck]:
    """Render the tiny shear cells, angle of repose and chute cooler decks into ``work_dir``.

    Parameters
    ----------
    work_dir : Path
        Directory that receives one sub-directory per deck (created if missing).
    config : Path, optional
        Configuration file; default ``config/tiny.yaml`` of the project.

    Returns
    -------
    list of BaseDeck
        The four decks, in the order split shear cell, ring shear cell, angle of repose,
        chute cooler.
    """
    root = Path(__file__).resolve().parents[2]
    config = config or root / "config" / "tiny.yaml"
    cfg = load_config(config)
    base = {
        "case_id": "fuzz",
        "coefficientFriction": 0.3,
        "coefficientRollingFriction": 0.1,
        "coefficientRestitution": 0.6,
        "density": 2500.0,
    }
    stress = cfg["shear_cell"]["normal_stresses"][0]
    decks = []
    render_case("shear_cell", {**base, "normal_stress": stress, "P": 0.8}, cfg, work_dir / "shear")
    decks.append(BaseDeck("shear_cell", work_dir / "shear", DECK_NAMES["shear_cell"]))
    ring = with_quick_ring(config)
    render_case("shear_cell", {**base, "normal_stress": stress, "P": 0.8}, ring, work_dir / "ring")
    decks.append(BaseDeck("ring_shear_cell", work_dir / "ring", DECK_NAMES["shear_cell"]))
    render_case("angle_of_repose", base, load_config(config), work_dir / "aor")
    decks.append(BaseDeck("angle_of_repose", work_dir / "aor", DECK_NAMES["angle_of_repose"]))
    render_chute_cooler(load_config(config), work_dir / "chute")
    decks.append(BaseDeck("chute_cooler", work_dir / "chute", CHUTE_DECK))
    return decks
