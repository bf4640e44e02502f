"""Screen the candidate grid against the measurements: Table 5, Figs. 6-9, the identified set."""

from demcal.core.rule_log import rule_log
from demcal.identification.identify import IdentificationFiles, identify
from demcal.sequential.round_steps import take_over


def main(snakemake) -> None:
    if getattr(snakemake.input, "screened", None):
        with rule_log(snakemake.log[0]) as logger:
            source = take_over(snakemake.input.screened, snakemake.output.identified)
            logger.info("the last round's screening and identified set (%s)", source)
        return
    with rule_log(snakemake.log[0]) as logger:
        result = identify(
            dict(zip(snakemake.params.outputs, snakemake.input.models, strict=True)),
            snakemake.input.experiment,
            snakemake.params.screening,
            snakemake.params.constants,
            dict(snakemake.config),
            IdentificationFiles(**dict(snakemake.output.items())),
            dataset=snakemake.input.dataset,
        )
        logger.info(
            "screened %d candidate sets in %.2f s; valid: %s",
            result.n_total,
            result.elapsed_s,
            {g: len(v) for g, v in result.valid.items()},
        )


main(snakemake)  # noqa: F821
