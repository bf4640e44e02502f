"""Render the chute-cooler deck, meshes and case.json (Snakemake script)."""

from demcal.application.chute_cooler.steps import render_from_config
from demcal.core.rule_log import rule_log


def main(snakemake) -> None:
    deck = snakemake.output.deck
    with rule_log(snakemake.log[0]) as logger:
        record = render_from_config(
            dict(snakemake.config), getattr(snakemake.input, "params", None), deck
        )
        s = record["setup"]
        logger.info(
            "rendered %s: parameters %s from %s; %d steps, about %.0f particles fed",
            deck,
            record["parameters"],
            record["parameters_source"],
            s["total_steps"],
            s["expected_particles"],
        )


main(snakemake)  # noqa: F821
