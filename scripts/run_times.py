"""Run time of every DEM case of the study, from the engine rules' benchmark files."""

from pathlib import Path

from demcal.bulk.run_times import write_run_times
from demcal.core.rule_log import rule_log


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]) as logger:
        # .../benchmarks/cases/<test>/<case>.tsv
        benchmarks = [
            (Path(path).parent.name, Path(path).stem, path) for path in snakemake.input.benchmarks
        ]
        table = write_run_times(benchmarks, snakemake.output.table, snakemake.output.figure)
        logger.info(
            "%d DEM cases, %.0f s of engine-rule wall-clock time in all",
            len(benchmarks),
            table["seconds"].sum(),
        )


main(snakemake)  # noqa: F821
