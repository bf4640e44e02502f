"""Run the chute-cooler deck with the configured engine; a failed run fails the rule."""

from pathlib import Path

from demcal.core.rule_log import rule_log
from demcal.engine_io.run import run_deck


def main(snakemake) -> None:
    deck, threads = Path(snakemake.input.deck), snakemake.threads
    with rule_log(snakemake.log[0]) as logger:
        status = run_deck(deck.parent, deck.name, snakemake.params.command, threads)
        if status["status"] != "ok":
            raise RuntimeError(f"{deck}: engine run failed: {status['error']}")
        logger.info("%s finished in %.1f s on %d thread(s)", deck, status["seconds"], threads)


main(snakemake)  # noqa: F821
