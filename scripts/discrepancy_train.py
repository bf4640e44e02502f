"""Discrepancy step 3 (Add): the surrogate of one bulk value of the extended model."""

import pandas as pd

from demcal.core.rule_log import rule_log
from demcal.discrepancy.extension import train_extended_surrogate
from demcal.discrepancy.runs import named_candidate


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        config = dict(snakemake.config)
        candidate = named_candidate(config, snakemake.input.ranking)
        meta = train_extended_surrogate(
            pd.read_csv(snakemake.input.dataset),
            snakemake.wildcards.output,
            dict(config["surrogate"]),
            [candidate.parameter],
            snakemake.output.model,
        )
        logger.info("%s: %s", snakemake.wildcards.output, meta)


main(snakemake)  # noqa: F821
