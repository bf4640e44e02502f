"""Logging set-up shared by the Snakemake scripts: everything, including a failure's traceback,
goes to the rule's ``log:`` file."""

import logging
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path


@contextmanager
def rule_log(path: str) -> Iterator[logging.Logger]:
    """Route logging to ``path`` for the duration of a rule; log and re-raise any exception.

    Parameters
    ----------
    path : str
        The rule's log file.
    """
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    logging.basicConfig(
        filename=path,
        level=logging.INFO,
        format="%(asctime)s %(levelname)s %(message)s",
        force=True,
    )
    logger = logging.getLogger("demcal")
    try:
        yield logger
    except Exception:
        logger.exception("rule failed")
        print(f"error: see {path}", file=sys.stderr)
        raise
