"""Screen the candidate grid against the measurements: Table 5, Figs. 6-9, the identified set."""

import json
from pathlib import Path

from demcal.core.experiments import load_experiment
from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log
from demcal.decks.material_block import material_block_text
from demcal.identification.calibration import calibrate, write_valid_sets
from demcal.identification.figures import box_plot_normalised, cor_density_plot, note_figure
from demcal.identification.statistics import table5_markdown, write_table5_csv
from demcal.surrogates.training import load_surrogate


def main(sm) -> None:
    out = sm.output
    with rule_log(sm.log[0]) as logger:
        surrogates = {
            name: load_surrogate(path)
            for name, path in zip(sm.params.outputs, sm.input.models, strict=True)
        }
        experiment = load_experiment(sm.input.experiment)
        result = calibrate(surrogates, experiment, sm.params.screening, sm.params.constants)
        logger.info(
            "screened %d candidate sets in %.2f s; valid: %s",
            result.n_total,
            result.elapsed_s,
            {g: len(v) for g, v in result.valid.items()},
        )
        write_valid_sets(result, Path(out.table5).parent)
        text = (
            f"# Table 5: valid parameter sets for {experiment.material}\n\n"
            f"{result.n_total} candidate sets screened in {result.elapsed_s:.2f} s; tolerance "
            f"{sm.params.screening['tolerance']:.0%}.\n\n"
        )
        text += (
            table5_markdown(result.table5) if len(result.table5) else "No measurement to match.\n"
        )
        Path(out.table5).write_text(text + "\n")
        write_table5_csv(result.table5, out.table5_csv)
        figures = {
            "fig6": ("SSC", "Fig. 6: shear cell"),
            "fig8": ("AoR", "Fig. 8: angle of repose"),
            "fig9": ("SSC & AoR", "Fig. 9: shear cell and angle of repose"),
        }
        for key, (group, title) in figures.items():
            valid = result.valid.get(group)
            if valid is not None and len(valid):
                box_plot_normalised(valid, getattr(out, key), title)
            else:
                note_figure(getattr(out, key), f"{title}: no valid sets or no measurement")
        ssc = result.valid.get("SSC")
        if ssc is not None and len(ssc):
            cor_density_plot(ssc, result.axes, out.fig7, title="Fig. 7: shear cell")
        else:
            note_figure(out.fig7, "Fig. 7: no valid shear-cell sets or no measurement")
        record = {
            "group": result.identified_group,
            "n_valid": {g: len(v) for g, v in result.valid.items()},
            "n_total": result.n_total,
            "parameters": result.identified,
        }
        Path(out.identified).write_text(json.dumps(record, indent=2) + "\n")
        write_sidecar(out.identified, dict(sm.config), seed=int(sm.params.screening["seed"]))
        if result.identified:
            means = {k: v["mean"] for k, v in result.identified.items()}
            block = material_block_text(
                means,
                dict(sm.config),
                f"identified ({result.identified_group}) mean parameters for {experiment.material}",
            )
        else:
            block = f"# no parameter set of the grid matches {experiment.material}\n"
        Path(out.material).write_text(block)


if __name__ == "__main__":
    main(snakemake)  # noqa: F821
