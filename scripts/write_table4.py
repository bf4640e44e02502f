"""Gather Table 4 of every bulk value, the hidden-size choices, the cross-validation and the
acceptance tolerance into one document (Markdown and CSV)."""

from demcal.core.rule_log import rule_log
from demcal.surrogates.table4 import write_table4_document


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        table = write_table4_document(
            list(snakemake.params.outputs),
            list(snakemake.input.tables),
            list(snakemake.input.sweeps),
            snakemake.output.markdown,
            csv=snakemake.output.csv,
            experiment=snakemake.input.experiment,
            tolerance=float(snakemake.params.tolerance),
        )
        for method, row in table.iterrows():
            logger.info(
                "%s %s: test R^2 %.3g, CV R^2 %.3g over %d folds, CV RMSE %.3g vs tolerance %.3g",
                row["output"],
                method,
                row["test_r2"],
                row["cv_r2"],
                row["cv_folds"],
                row["cv_rmse"],
                row["tolerance_abs"],
            )


main(snakemake)  # noqa: F821
