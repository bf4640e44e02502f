"""Run the chute-cooler deck with the configured engine; a failed run fails the rule."""

from pathlib import Path

from demcal.core.rule_log import rule_log
from demcal.engine_io.run import run_deck


def main(deck: str, command: str, threads: int, log: str) -> None:
    with rule_log(log) as logger:
        status = run_deck(Path(deck).parent, Path(deck).name, command, threads)
        if status["status"] != "ok":
            raise RuntimeError(f"{deck}: engine run failed: {status['error']}")
        logger.info("%s finished in %.1f s on %d thread(s)", deck, status["seconds"], threads)


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main(sm.input.deck, sm.params.command, sm.threads, sm.log[0])
