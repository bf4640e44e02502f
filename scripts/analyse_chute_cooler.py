"""Segregation in the analysed box of the chute-cooler run: table, index, time series."""

from demcal.application.chute_cooler.steps import write_analysis
from demcal.core.rule_log import rule_log


def main(snakemake) -> None:
    out = snakemake.output
    with rule_log(snakemake.log[0]) as logger:
        result, _, setup = write_analysis(
            snakemake.input.status,
            dict(snakemake.config),
            out.table,
            out.index,
            out.series,
            out.steady,
        )
        if not result.window.steady:
            logger.warning("box %d NOT steady: %s", setup.analysed_box, result.window.reason)
        logger.info(
            "S = %.4f (normalised %.3f) over %.3g-%.3g s",
            result.index.index,
            result.index.normalised,
            result.window.start_time,
            result.window.end_time,
        )


main(snakemake)  # noqa: F821
