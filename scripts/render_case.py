"""Render the deck, meshes and case.json of one DEM case (Snakemake script)."""

from pathlib import Path

from demcal.decks import render_case
from demcal.rule_log import rule_log


def main(test: str, case: dict, config: dict, deck: str, log: str) -> None:
    with rule_log(log) as logger:
        info = render_case(test, case, config, Path(deck).parent)
        logger.info("rendered %s case %s: %s", test, case["case_id"], info.get("deck"))


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main(sm.wildcards.test, dict(sm.params.case), dict(sm.config), sm.output.deck, sm.log[0])
