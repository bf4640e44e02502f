"""Identification of a material from its measurements: screen the candidate grid with the trained
surrogates and write Table 5, the valid sets, Figs. 6-9, the identified parameter set and its
LIGGGHTS material block.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.core.experiments import load_experiment
from demcal.core.provenance import write_sidecar
from demcal.decks.material_block import material_block_text
from demcal.identification.calibration import CalibrationResult, calibrate, write_valid_sets
from demcal.identification.figures import box_plot_normalised, cor_density_plot, note_figure
from demcal.identification.reachability import reach_of_measurements, reach_statement
from demcal.identification.statistics import table5_markdown, write_table5_csv
from demcal.surrogates.training import load_screening_surrogate

#: Box-plot figures: file key -> (group of valid sets, title).
BOX_PLOT_FIGURES = {
    "fig6": ("SSC", "Fig. 6: shear cell"),
    "fig8": ("AoR", "Fig. 8: angle of repose"),
    "fig9": ("SSC & AoR", "Fig. 9: shear cell and angle of repose"),
}


@dataclass(frozen=True)
class IdentificationFiles:
    """The files the identification writes (the valid sets go beside ``table5``).

    Attributes
    ----------
    table5, table5_csv : str or Path
        Table 5 as markdown (with a heading and the screening summary) and as CSV.
    identified : str or Path
        JSON record of the identified set (group, valid counts, per-parameter statistics), with
        a provenance sidecar ``<identified>.json``.
    material : str or Path
        LIGGGHTS material block of the identified mean parameters.
    fig6, fig7, fig8, fig9 : str or Path
        Figures (PNG) of the valid sets; a note figure where a group has none.
    """

    table5: str | Path
    table5_csv: str | Path
    identified: str | Path
    material: str | Path
    fig6: str | Path
    fig7: str | Path
    fig8: str | Path
    fig9: str | Path


def screened_with_statement(methods: Mapping[str, str], choice: str) -> str:
    """One sentence naming the surrogate that screened each bulk value.

    Parameters
    ----------
    methods : mapping
        Bulk value -> Table 4 method (``"ANN"``, ``"Gaussian"`` or ``"Bayesian"``).
    choice : str
        ``surrogate.screen_with``.
    """
    names = {"ANN": "network", "Gaussian": "Gaussian process", "Bayesian": "linear regression"}
    parts = ", ".join(f"{value} by its {names[m]}" for value, m in methods.items())
    rule = (
        " (highest cross-validated R^2; the linear regression only where its CV RMSE is below"
        " the tolerance)"
        if choice == "best"
        else ""
    )
    return f"screened {parts}{rule}."


def identify(
    models: Mapping[str, str | Path],
    experiment_file: str | Path,
    screening: Mapping[str, Any],
    constants: Mapping[str, Mapping[str, float]],
    config: Mapping[str, Any],
    files: IdentificationFiles,
    dataset: str | Path | None = None,
) -> CalibrationResult:
    """Screen the candidate grid against the measurements and write every identification file.

    Parameters
    ----------
    models : mapping of str to path
        Bulk value (``mu_psh``, ``mu_sh``, ``rho_b``, ``aor``) -> saved network (``model.pt``
        with its sidecar; its Table 4 and Gaussian process beside it). The surrogate that
        screens is chosen by ``surrogate.screen_with`` of ``config``
        (:func:`demcal.surrogates.training.load_screening_surrogate`).
    experiment_file : path
        The measured bulk values (``config/experiments/*.yaml``).
    screening : mapping
        The ``screening`` config section (axes, seed, chunk_size, threads, tolerance,
        measurement_coverage).
    constants : mapping
        Bulk value -> network inputs held constant (e.g. the test's dCylDp).
    config : mapping
        The validated configuration (sidecar and material block).
    files : IdentificationFiles
        Where to write.
    dataset : path, optional
        The bulk-value dataset the networks were trained on; when given, the first line of
        Table 5 and the identified-set record say whether every measured value lies within
        the range of its DEM runs (:mod:`demcal.identification.reachability`).

    Returns
    -------
    CalibrationResult
        Valid sets per group, Table 5 and the identified set.
    """
    choice = str(config["surrogate"]["screen_with"])
    experiment = load_experiment(experiment_file)
    tol = float(screening["tolerance"])
    coverage = float(screening["measurement_coverage"])
    loaded = {
        name: load_screening_surrogate(path, choice, experiment, tol)
        for name, path in models.items()
    }
    surrogates = {name: (model, features) for name, (model, features, _) in loaded.items()}
    methods = {name: method for name, (_, _, method) in loaded.items()}
    result = calibrate(surrogates, experiment, screening, constants)
    write_valid_sets(result, Path(files.table5).parent)
    reach = None
    if dataset is not None:
        reach = reach_of_measurements(pd.read_csv(dataset), experiment, tol)
    statement = reach_statement(reach, experiment.material) + "\n\n" if reach else ""
    mean_line = (
        mean_set_statement(result.at_identified, tol, coverage) if result.at_identified else ""
    )
    if mean_line:
        statement += mean_line + "\n\n"
    text = statement + (
        f"# Table 5: valid parameter sets for {experiment.material}\n\n"
        f"{result.n_total} candidate sets screened in {result.elapsed_s:.2f} s; accepted "
        f"within {tolerance_text(tol, coverage)}; {screened_with_statement(methods, choice)}"
        "\n\n"
    )
    text += table5_markdown(result.table5) if len(result.table5) else "No measurement to match.\n"
    Path(files.table5).write_text(text + "\n")
    write_table5_csv(result.table5, files.table5_csv)
    _write_figures(result, files)
    record = {
        "group": result.identified_group,
        "n_valid": {g: len(v) for g, v in result.valid.items()},
        "n_total": result.n_total,
        "parameters": result.identified,
        "screened_with": methods,
    }
    if result.at_identified:
        record["predicted_at_mean"] = result.at_identified
        record["mean_accepted"] = all(r["within_tolerance"] for r in result.at_identified)
        record["mean_set"] = mean_line
    if reach is not None:
        record["reachable"] = all(r.reachable for r in reach)
        record["reach"] = reach_statement(reach, experiment.material)
    Path(files.identified).write_text(json.dumps(record, indent=2) + "\n")
    write_sidecar(files.identified, dict(config), seed=int(screening["seed"]))
    if result.identified:
        means = {k: v["mean"] for k, v in result.identified.items()}
        block = material_block_text(
            means,
            dict(config),
            f"identified ({result.identified_group}) mean parameters for {experiment.material}",
        )
    else:
        block = f"# no parameter set of the grid matches {experiment.material}\n"
    Path(files.material).write_text(block)
    return result


def _condition(row: Mapping[str, Any]) -> str:
    if row["normal_stress"] is None:
        return row["observable"]
    return f"{row['observable']} at {row['normal_stress']:g} Pa, P = {row['P']:g}"


def tolerance_text(tol: float, coverage: float = 0.0) -> str:
    """The acceptance rule in words, e.g. "the 5% tolerance" (no trailing full stop).

    Parameters
    ----------
    tol : float
        Relative acceptance tolerance.
    coverage : float
        Standard deviations of a measured value that widen its band (``screening``
        ``measurement_coverage``).
    """
    if coverage == 0.0:
        return f"the {tol:.0%} tolerance"
    return (
        f"the {tol:.0%} tolerance widened by {coverage:g} standard deviations of each measured "
        "value that states one"
    )


def mean_set_statement(at_mean: list[dict[str, Any]], tol: float, coverage: float = 0.0) -> str:
    """One line on whether the surrogates accept the identified mean set itself.

    Parameters
    ----------
    at_mean : list of dict
        :func:`demcal.identification.calibration.predictions_at` at the identified means.
    tol : float
        Relative acceptance tolerance.
    coverage : float
        Standard deviations of a measured value that widen its band.

    Returns
    -------
    str
        A single line (no trailing newline).
    """
    rule = tolerance_text(tol, coverage)
    missed = [r for r in at_mean if not r["within_tolerance"]]
    if not missed:
        return (
            f"At the identified mean set the surrogates predict every measured value within {rule}."
        )
    parts = "; ".join(
        f"{_condition(r)} {r['predicted']:.4g} against {r['measured']:.4g} "
        f"({r['deviation']:.1%} off)"
        for r in missed
    )
    return (
        f"**The identified mean set is not itself a valid set**: there the surrogates predict "
        f"{parts}, beyond {rule}. The valid sets lie around it, not at it (a "
        "curved or thin valid region), so the verification at the mean is expected to miss "
        "by about as much: read it before using material.in."
    )


def _write_figures(result: CalibrationResult, files: IdentificationFiles) -> None:
    """Figs. 6, 8, 9 (box plots) and Fig. 7 (COR density), or a note where a group is empty."""
    for key, (group, title) in BOX_PLOT_FIGURES.items():
        valid = result.valid.get(group)
        if valid is not None and len(valid):
            box_plot_normalised(valid, getattr(files, key), title)
        else:
            note_figure(getattr(files, key), f"{title}: no valid sets or no measurement")
    ssc = result.valid.get("SSC")
    if ssc is not None and len(ssc):
        cor_density_plot(ssc, result.axes, files.fig7, title="Fig. 7: shear cell")
    else:
        note_figure(files.fig7, "Fig. 7: no valid shear-cell sets or no measurement")
