"""Discrepancy step 4 (Show): gap before and after, figure, verification and summary."""

from demcal.core.rule_log import rule_log
from demcal.discrepancy.before_after import write_before_after


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        inp, out = snakemake.input, snakemake.output
        # The extended model's inputs exist only when an effect was named.
        summary = write_before_after(
            dict(snakemake.config),
            inp.find,
            inp.find_table,
            inp.ranking,
            inp.reference,
            out.table,
            out.figure,
            out.verification,
            out.summary,
            recalibration_path=inp.get("recalibration"),
            after_table_path=inp.get("after_table"),
            verification_files=inp.get("verification"),
            experiment_path=inp.experiment,
        )
        logger.info("summary: %s", summary)


main(snakemake)  # noqa: F821
