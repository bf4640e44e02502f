"""Fig. 11 (grouped bars), Fig. 10 (3-D layout) and the ParaView files of the chute cooler."""

from demcal.application.chute_cooler.steps import write_figures
from demcal.core.rule_log import rule_log


def main(snakemake) -> None:
    out = snakemake.output
    with rule_log(snakemake.log[0]) as logger:
        files = write_figures(
            snakemake.input.status, snakemake.input.table, out.fig11, out.fig10, out.vtk
        )
        logger.info(
            "wrote %s, %s and %d ParaView files", files.fig11, files.fig10, len(files.paraview)
        )


main(snakemake)  # noqa: F821
