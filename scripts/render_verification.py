"""Render a verification case at the identified mean parameter set."""

from pathlib import Path

from demcal.core.rule_log import rule_log
from demcal.identification.verification_run import render_verification_case


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        case = render_verification_case(
            snakemake.input.identified,
            snakemake.wildcards.test,
            snakemake.wildcards.case,
            dict(snakemake.config),
            Path(snakemake.output.deck).parent,
        )
        logger.info("verification case %s: %s", snakemake.wildcards.case, case)


main(snakemake)  # noqa: F821
