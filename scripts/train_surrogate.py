"""Train the network of one bulk value with its baselines (Snakemake script)."""

from demcal.core.rule_log import rule_log
from demcal.sequential.round_steps import take_over
from demcal.surrogates.training import train_from_dataset


def main(snakemake) -> None:
    output = snakemake.wildcards.output
    if getattr(snakemake.input, "trained", None):
        with rule_log(snakemake.log[0]) as logger:
            source = take_over(snakemake.input.trained, snakemake.output.model)
            logger.info("%s: the last round's network and Table 4 rows (%s)", output, source)
        return
    with rule_log(snakemake.log[0]) as logger:
        trained = train_from_dataset(
            snakemake.input.dataset,
            output,
            dict(snakemake.params.settings),
            snakemake.output.model,
            dict(snakemake.config),
        )
        sweep = trained.sweep
        logger.info(
            "%s: %d samples, inputs %s; selected %d hidden neurons (generalisation error), "
            "paper rule would pick %d",
            output,
            trained.n_samples,
            trained.features,
            sweep.selected_size,
            sweep.paper_rule_size,
        )
        for method, row in trained.table4.iterrows():
            logger.info(
                "%s %s: test R^2 %.3g (%d sets), cross-validated R^2 %.3g, RMSE %.3g "
                "(%d folds over %d sets)",
                output,
                method,
                row["test_r2"],
                row["test_sets"],
                row["cv_r2"],
                row["cv_rmse"],
                row["cv_folds"],
                row["cv_sets"],
            )


main(snakemake)  # noqa: F821
