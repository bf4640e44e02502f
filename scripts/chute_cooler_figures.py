"""Fig. 11 (grouped bars), Fig. 10 (3-D layout) and the ParaView files of the chute cooler."""

from pathlib import Path

import pandas as pd

from demcal.application.chute_cooler.analysis import export_paraview, render_layout
from demcal.application.chute_cooler.deck import load_case
from demcal.application.chute_cooler.figures import plot_fig11
from demcal.application.chute_cooler.segregation import segregation_index, table_volumes
from demcal.core.rule_log import rule_log


def main(inputs: dict, outputs: dict, log: str) -> None:
    with rule_log(log) as logger:
        case_dir = Path(inputs["status"]).parent
        _, setup = load_case(case_dir)
        table = pd.read_csv(inputs["table"])
        index = segregation_index(*table_volumes(table, inputs["table"]))
        plot_fig11(table, index, outputs["fig11"], box_label=f"box {setup.analysed_box}")
        render_layout(case_dir, outputs["fig10"])
        files = export_paraview(case_dir, outputs["vtk"])
        logger.info(
            "wrote %s, %s and %d ParaView files", outputs["fig11"], outputs["fig10"], len(files)
        )


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main(dict(sm.input.items()), dict(sm.output.items()), sm.log[0])
