"""Choose the parameter sets of the next round of a sequential study."""

import json
from pathlib import Path

from demcal.core.rule_log import rule_log
from demcal.sequential.round_steps import write_next_design


def main(snakemake) -> None:
    with rule_log(snakemake.log[0]):
        record = snakemake.input.record[0]
        if json.loads(Path(record).read_text())["stop"]:
            raise ValueError(f"{record}: the study stopped after that round; there is no next one")
        write_next_design(
            dict(snakemake.config),
            int(snakemake.wildcards.round),
            snakemake.input.dataset[0],
            list(snakemake.input.verification),
            snakemake.input.identified[0],
            snakemake.input.experiment,
            snakemake.params.constants,
            snakemake.output.design,
            snakemake.output.choices,
        )


main(snakemake)  # noqa: F821
