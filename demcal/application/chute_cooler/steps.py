"""The steps of the chute-cooler application as the workflow runs them: render the case, analyse
the finished run, draw the figures. Each step writes its files to the paths it is given.
"""

from __future__ import annotations

import json
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pandas as pd

from demcal.application.chute_cooler.analysis import (
    analyse_run,
    export_paraview,
    index_summary,
    read_system_table,
    render_layout,
    write_json,
)
from demcal.application.chute_cooler.box_layers import table_volumes
from demcal.application.chute_cooler.deck import (
    load_case,
    read_identified_parameters,
    render_chute_cooler,
)
from demcal.application.chute_cooler.figures import plot_fig11, plot_steady_state
from demcal.application.chute_cooler.layout import ChuteCoolerSetup
from demcal.application.chute_cooler.segregation import segregation_index
from demcal.application.chute_cooler.steady_segregation import SegregationResult
from demcal.core.provenance import write_sidecar


def render_from_config(
    config: Mapping[str, Any], identified_file: str | Path | None, deck: str | Path
) -> dict[str, Any]:
    """Render the chute-cooler case whose deck is ``deck`` (meshes and ``case.json`` beside it).

    Parameters
    ----------
    config : mapping
        The validated configuration.
    identified_file : path or None
        ``identified_parameters.json``, used when ``application.parameters`` is null; None
        when the configuration gives the parameters.
    deck : path
        The deck file; its directory is the case directory.

    Returns
    -------
    dict
        The content of ``case.json``.
    """
    identified = read_identified_parameters(identified_file) if identified_file else None
    return render_chute_cooler(
        config, Path(deck).parent, identified, identified_file or "identified parameters"
    )


def write_analysis(
    status: str | Path,
    config: Mapping[str, Any],
    table: str | Path,
    index: str | Path,
    series: str | Path,
    steady: str | Path,
) -> tuple[SegregationResult, dict[str, Any], ChuteCoolerSetup]:
    """Analyse the finished run beside ``status`` and write its segregation files.

    Parameters
    ----------
    status : path
        ``status.json`` of the run; its directory is the case directory.
    config : mapping
        The validated configuration (sidecar of the table).
    table : path
        Layer table of the steady window (CSV), with a provenance sidecar ``<table>.json``.
    index : path
        The index summary, ``segregation_index.json`` (see ``analysis.index_summary``).
    series : path
        The time series of the analysed box (CSV).
    steady : path
        Figure of the time series with the averaging window (PNG).

    Returns
    -------
    result : SegregationResult
        Table, index, series and window.
    summary : dict
        The content of ``index``.
    setup : ChuteCoolerSetup
        The set-up of the run.
    """
    case_dir = Path(status).parent
    result, record, setup = analyse_run(case_dir)
    run_status = json.loads(Path(status).read_text())
    summary = index_summary(result, record, run_status)
    Path(table).parent.mkdir(parents=True, exist_ok=True)
    result.table.to_csv(table, index=False)
    result.series.to_csv(series, index=False)
    write_json(summary, index)
    plot_steady_state(
        result.series,
        result.window,
        steady,
        read_system_table(case_dir),
        box_label=f"box {setup.analysed_box}",
    )
    write_sidecar(table, config, seed=int(config["seed"]), extra={"index": summary})
    return result, summary, setup


@dataclass(frozen=True)
class FigureFiles:
    """What :func:`write_figures` wrote: Fig. 11, Fig. 10 and the ParaView files."""

    fig11: Path
    fig10: Path
    paraview: list[Path]


def write_figures(
    status: str | Path, table: str | Path, fig11: str | Path, fig10: str | Path, vtk: str | Path
) -> FigureFiles:
    """Fig. 11 (grouped bars), Fig. 10 (3-D layout) and the ParaView files of the run.

    Parameters
    ----------
    status : path
        ``status.json`` of the run; its directory is the case directory.
    table : path
        The layer table written by :func:`write_analysis`.
    fig11, fig10 : path
        The figures (PNG).
    vtk : path
        Directory for the particle and wall VTK files.
    """
    case_dir = Path(status).parent
    _, setup = load_case(case_dir)
    layers = pd.read_csv(table)
    index = segregation_index(*table_volumes(layers, str(table)))
    plot_fig11(layers, index, fig11, box_label=f"box {setup.analysed_box}")
    render_layout(case_dir, fig10)
    files = export_paraview(case_dir, vtk)
    return FigureFiles(Path(fig11), Path(fig10), files)
