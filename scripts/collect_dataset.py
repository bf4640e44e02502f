"""Collect every case's bulk values into the tidy dataset; list and count failed cases."""

import pandas as pd

from demcal.bulk.dataset import collect
from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log


def main(inputs: list[str], dataset: str, failed: str, config: dict, log: str) -> None:
    with rule_log(log) as logger:
        data = collect(pd.read_csv(path) for path in inputs)
        data.to_csv(dataset, index=False, float_format="%.10g")
        bad = data[data["status"] != "ok"].drop_duplicates("case_id")
        bad[["test", "case_id", "error"]].to_csv(failed, index=False)
        if len(bad):
            logger.warning(
                "%d of %d DEM cases failed and are excluded from training: %s",
                len(bad),
                data["case_id"].nunique(),
                ", ".join(bad["case_id"]),
            )
        write_sidecar(
            dataset,
            config,
            extra={
                "rows": len(data),
                "cases": int(data["case_id"].nunique()),
                "failed_cases": len(bad),
            },
        )
        logger.info("dataset: %d rows from %d files", len(data), len(inputs))


if __name__ == "__main__":
    sm = snakemake  # noqa: F821
    main(list(sm.input.bulk), sm.output.dataset, sm.output.failed, dict(sm.config), sm.log[0])
