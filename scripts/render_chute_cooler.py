"""Render the chute-cooler deck, meshes and case.json (Snakemake script)."""

from pathlib import Path

from demcal.application.chute_cooler.deck import read_identified_parameters, render_chute_cooler
from demcal.core.rule_log import rule_log


def main(config: dict, params_file: str | None, deck: str, log: str) -> None:
    with rule_log(log) as logger:
        identified = read_identified_parameters(params_file) if params_file else None
        record = render_chute_cooler(
            config, Path(deck).parent, identified, params_file or "identified parameters"
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


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    params_file = getattr(sm.input, "params", None)
    main(dict(sm.config), params_file, sm.output.deck, sm.log[0])
