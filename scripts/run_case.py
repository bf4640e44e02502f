"""Run one deck with the configured engine; a failed run is recorded, not raised."""

from pathlib import Path

from demcal.core.rule_log import rule_log
from demcal.engine_io.run import run_deck


def main(snakemake) -> None:
    deck = Path(snakemake.input.deck)
    with rule_log(snakemake.log[0]) as logger:
        status = run_deck(deck.parent, deck.name, snakemake.params.command, snakemake.threads)
        if status["status"] == "ok":
            logger.info("%s finished in %.1f s", deck, status["seconds"])
        else:
            # Recorded in status.json, excluded from training and counted in the report.
            logger.warning("%s FAILED: %s", deck, status["error"])


main(snakemake)  # noqa: F821
