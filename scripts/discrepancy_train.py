"""Discrepancy step 3 (Add): the surrogate of one bulk value of the extended model."""

import json
from pathlib import Path

import pandas as pd

from demcal.core.rule_log import rule_log
from demcal.discrepancy.extension import train_extended_surrogate
from demcal.discrepancy.runs import candidate_by_name


def main(sm) -> None:
    with rule_log(sm.log[0]) as logger:
        config = dict(sm.config)
        record = json.loads(Path(sm.input.ranking).read_text())
        candidate = candidate_by_name(config, record["winner"])
        meta = train_extended_surrogate(
            pd.read_csv(sm.input.dataset),
            sm.wildcards.output,
            dict(config["surrogate"]),
            [candidate.parameter],
            sm.output.model,
        )
        logger.info("%s: %s", sm.wildcards.output, meta)


if __name__ == "__main__":
    main(snakemake)  # noqa: F821
