"""Train the network of one bulk value with its baselines (Snakemake script)."""

from pathlib import Path

import pandas as pd

from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log
from demcal.surrogates.training import train_output


def main(dataset: str, output: str, settings: dict, model: str, config: dict, log: str) -> None:
    with rule_log(log) as logger:
        data = pd.read_csv(dataset)
        trained = train_output(data, output, settings, Path(model).parent)
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
        write_sidecar(Path(model).parent / "table4.csv", config, seed=int(settings["seed"]))


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main(
        sm.input.dataset,
        sm.wildcards.output,
        dict(sm.params.settings),
        sm.output.model,
        dict(sm.config),
        sm.log[0],
    )
