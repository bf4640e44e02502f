"""Render a verification case at the identified mean parameter set."""

import json
from pathlib import Path

from demcal.core.rule_log import rule_log
from demcal.decks.render import render_case
from demcal.design.cases import verification_case


def main(sm) -> None:
    with rule_log(sm.log[0]) as logger:
        identified = json.loads(Path(sm.input.identified).read_text())
        case = verification_case(dict(sm.config), identified, sm.wildcards.test, sm.wildcards.case)
        render_case(sm.wildcards.test, case, dict(sm.config), Path(sm.output.deck).parent)
        logger.info("verification case %s: %s", sm.wildcards.case, case)


if __name__ == "__main__":
    main(snakemake)  # noqa: F821
