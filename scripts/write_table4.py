"""Gather Table 4 of every bulk value and the hidden-size choices into one document."""

import pandas as pd

from demcal.core.rule_log import rule_log
from demcal.surrogates.metrics import to_markdown
from demcal.surrogates.network import select_by_test_r2, select_by_validation


def main(outputs: list[str], tables: list[str], sweeps: list[str], markdown: str, log: str) -> None:
    with rule_log(log):
        parts = ["# Table 4: regression methods compared on the test set\n"]
        for name, table, sweep in zip(outputs, tables, sweeps, strict=True):
            t4 = pd.read_csv(table, index_col=0)
            sw = pd.read_csv(sweep)
            parts.append(
                f"## {name}\n\nNetwork size chosen by generalisation-set error: "
                f"{select_by_validation(sw)} hidden neurons; the paper's rule (best test R^2) "
                f"would pick {select_by_test_r2(sw)}.\n\n{to_markdown(t4, float_format='.3g')}\n"
            )
        with open(markdown, "w") as fh:
            fh.write("\n".join(parts))


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main(
        list(sm.params.outputs),
        list(sm.input.tables),
        list(sm.input.sweeps),
        sm.output.markdown,
        sm.log[0],
    )
