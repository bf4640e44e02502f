"""Gather Table 4 of every bulk value and the hidden-size choices into one document."""

from demcal.core.rule_log import rule_log
from demcal.surrogates.training import write_table4_document


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]):
        write_table4_document(
            list(snakemake.params.outputs),
            list(snakemake.input.tables),
            list(snakemake.input.sweeps),
            snakemake.output.markdown,
        )


main(snakemake)  # noqa: F821
