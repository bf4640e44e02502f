"""Discrepancy step 3 (Add): recalibrate the extended model (its magnitude as one more axis)."""

import json
from pathlib import Path

from demcal.core.experiments import load_experiment
from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log
from demcal.discrepancy.report import find_markdown
from demcal.discrepancy.runs import candidate_by_name
from demcal.discrepancy.workflow import recalibrate


def main(sm) -> None:
    with rule_log(sm.log[0]) as logger:
        config = dict(sm.config)
        ranking = json.loads(Path(sm.input.ranking).read_text())
        candidate = candidate_by_name(config, ranking["winner"])
        experiment = load_experiment(sm.input.experiment)
        paths = dict(zip(sm.params.outputs, sm.input.models, strict=True))
        result, box, record = recalibrate(paths, experiment, config, candidate)
        result.observations.to_csv(sm.output.table, index=False, float_format="%.8g")
        Path(sm.output.record).write_text(json.dumps(record, indent=2) + "\n")
        Path(sm.output.markdown).write_text(
            find_markdown(result, f"{experiment.material}, model + {candidate.name}", box.bounds)
        )
        write_sidecar(sm.output.record, config)
        logger.info("extended model: %s; best point %s", result.verdict, record["point"])


if __name__ == "__main__":
    main(snakemake)  # noqa: F821
