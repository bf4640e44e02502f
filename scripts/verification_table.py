"""Compare the verification DEM runs at the identified set (one list of runs per engine) with
the measurements and with each other."""

from demcal.core.rule_log import rule_log
from demcal.identification.verification_run import write_verification_table


def main(snakemake) -> None:
    engines = snakemake.params.engines
    with rule_log(snakemake.log[0]):
        write_verification_table(
            {engine: getattr(snakemake.input, f"bulk_{engine}") for engine in engines},
            snakemake.input.experiment,
            snakemake.params.tolerance,
            snakemake.output.csv,
            snakemake.output.table,
            commands=engines,
            threads=snakemake.params.threads,
            identified=snakemake.input.identified,
        )


main(snakemake)  # noqa: F821
