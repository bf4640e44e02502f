"""Discrepancy step 2 (Name): score the candidate effects with their probe runs, rank them and
write the extended design of the winner."""

import json
from pathlib import Path

import pandas as pd

from demcal.core.experiments import load_experiment
from demcal.core.provenance import write_sidecar
from demcal.core.rule_log import rule_log
from demcal.discrepancy.candidates import extended_design
from demcal.discrepancy.extension import read_runs
from demcal.discrepancy.report import ranking_markdown
from demcal.discrepancy.workflow import rank


def main(sm) -> None:
    with rule_log(sm.log[0]) as logger:
        config = dict(sm.config)
        settings = config["discrepancy"]
        find = json.loads(Path(sm.input.find).read_text())
        out = sm.output
        if not find["missing"]:
            # Nothing is missing: the ranking is not run, the outputs say why.
            empty = pd.DataFrame(columns=["rank", "candidate", "status"])
            empty.to_csv(out.table, index=False)
            Path(out.markdown).write_text(
                ranking_markdown(empty, None, 0, 0.0, verdict=find["verdict"])
            )
            record = {"winner": None, "ran": False, "reason": find["verdict"], "ranking": []}
            Path(out.record).write_text(json.dumps(record, indent=2) + "\n")
            pd.DataFrame(columns=["case_id"]).to_csv(out.design, index=False)
            pd.DataFrame(columns=["case_id"]).to_csv(out.probes, index=False)
            logger.info("nothing missing; ranking not run")
            return
        experiment = load_experiment(sm.input.experiment)
        paths = dict(zip(sm.params.outputs, sm.input.models, strict=True))
        runs = read_runs(sm.input.probes)
        runs.to_csv(out.probes, index=False, float_format="%.8g")
        result = rank(paths, experiment, config, runs, find["point"])
        result.table.to_csv(out.table, index=False, float_format="%.6g")
        n_obs = len(result.find.observations)
        Path(out.markdown).write_text(
            ranking_markdown(
                result.table,
                result.winner.name if result.winner else None,
                n_obs,
                float(settings["min_delta_bic"]),
                float(settings["min_explained"]),
                result.notes,
            )
        )
        scored = result.table[result.table["rank"].notna()]
        record = {
            "winner": result.winner.name if result.winner else None,
            "ran": True,
            "n_observations": n_obs,
            "null_deviance": result.null_deviance,
            "notes": result.notes,
            "ranking": [
                {
                    "candidate": r.candidate,
                    "delta_bic": float(r.delta_bic),
                    "magnitude": float(r.magnitude),
                    "explained": float(r.explained),
                }
                for r in scored.itertuples()
            ],
        }
        if result.winner is not None:
            fit = result.fits[result.winner.name]
            record.update(
                {
                    "parameter": result.winner.parameter,
                    "magnitude": fit.magnitude,
                    "theta": fit.best.theta,
                }
            )
            ext = settings["extended"]
            design = extended_design(config, result.winner, int(ext["n"]), int(ext["seed"]))
            design.to_csv(out.design, index=False, float_format="%.12g")
        else:
            pd.DataFrame(columns=["case_id"]).to_csv(out.design, index=False)
        Path(out.record).write_text(json.dumps(record, indent=2) + "\n")
        write_sidecar(out.record, config)
        logger.info("ranking:\n%s", result.table.to_string())


if __name__ == "__main__":
    main(snakemake)  # noqa: F821
