"""Discrepancy step 3 (Add): the training data of the extended model."""

import json
from pathlib import Path

import pandas as pd

from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log
from demcal.discrepancy.extension import extended_training_data, read_runs
from demcal.discrepancy.runs import candidate_by_name


def main(sm) -> None:
    with rule_log(sm.log[0]) as logger:
        config = dict(sm.config)
        record = json.loads(Path(sm.input.ranking).read_text())
        candidate = candidate_by_name(config, record["winner"])
        base = pd.read_csv(sm.input.dataset)
        data = extended_training_data(
            base,
            read_runs(sm.input.probes),
            read_runs(sm.input.extended),
            candidate,
            list(sm.params.tests),
        )
        data.to_csv(sm.output.dataset, index=False, float_format="%.10g")
        write_sidecar(sm.output.dataset, config, extra={"rows": len(data)})
        logger.info("extended training data: %s", data["source"].value_counts().to_dict())


if __name__ == "__main__":
    main(snakemake)  # noqa: F821
