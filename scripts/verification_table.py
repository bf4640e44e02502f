"""Compare the verification DEM runs at the identified set with the measurements."""

import pandas as pd

from demcal.core.experiments import load_experiment
from demcal.core.rule_log import rule_log
from demcal.identification.verification import verification_table


def main(sm) -> None:
    with rule_log(sm.log[0]):
        runs = pd.concat([pd.read_csv(p) for p in sm.input.bulk], ignore_index=True)
        table = verification_table(
            runs, load_experiment(sm.input.experiment), float(sm.params.tolerance)
        )
        table.to_csv(sm.output.csv, index=False)
        with open(sm.output.table, "w") as fh:
            fh.write("# Verification: DEM at the identified mean set vs measurement\n\n")
            fh.write(table.to_string(index=False) + "\n")


if __name__ == "__main__":
    main(snakemake)  # noqa: F821
