"""Discrepancy step 1 (Find): best achievable misfit of the current model, gap and verdict."""

import json
from pathlib import Path

from demcal.core.experiments import load_experiment
from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log
from demcal.discrepancy.report import find_markdown
from demcal.discrepancy.workflow import find_from_files, find_record


def main(sm) -> None:
    with rule_log(sm.log[0]) as logger:
        config = dict(sm.config)
        experiment = load_experiment(sm.input.experiment)
        paths = dict(zip(sm.params.outputs, sm.input.models, strict=True))
        result, _, box = find_from_files(paths, experiment, config)
        record = find_record(result, box, config)
        result.observations.to_csv(sm.output.table, index=False, float_format="%.8g")
        Path(sm.output.record).write_text(json.dumps(record, indent=2) + "\n")
        Path(sm.output.markdown).write_text(find_markdown(result, experiment.material, box.bounds))
        write_sidecar(sm.output.record, config)
        logger.info("%s; theta* = %s", result.verdict, result.best.theta)


if __name__ == "__main__":
    main(snakemake)  # noqa: F821
