# demcal: DEM contact-parameter calibration from bulk experiments.
# Table of contents: configuration, validation, the stages, and the default target.
from snakemake.utils import min_version

min_version("9.0")


configfile: "config/config.yaml"


include: "workflow/rules/common.smk"


wildcard_constraints:
    test="shear_cell|angle_of_repose",
    case=r"[A-Za-z0-9]+(_r\d+)?(_s\d+(_p\d+)?|_h\d+)?",
    stage="cases|verification/[a-z][a-z0-9_]*|sequential/round_[0-9]+/verification|discrepancy/probes|discrepancy/reprobes|discrepancy/extended|discrepancy/verification",
    engine="[a-z][a-z0-9_]*",
    output="mu_psh|mu_sh|rho_b|aor",


include: "workflow/rules/design.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/bulk.smk"
include: "workflow/rules/surrogate.smk"
include: "workflow/rules/identify.smk"
include: "workflow/rules/application.smk"
include: "workflow/rules/discrepancy.smk"


if SEQUENTIAL:

    include: "workflow/rules/sequential.smk"


rule all:
    default_target: True
    input:
        design=DESIGN_TABLE,
        dataset=DATASET,
        run_times=f"{RESULTS}/bulk/run_times.csv",
        table4=f"{RESULTS}/surrogates/table4.md",
        table5=f"{RESULTS}/identification/table5.md",
        verification=f"{RESULTS}/verification/verification.md",
        verification_heap=f"{RESULTS}/verification/pictures/heap.png",
        verification_shear_cell=f"{RESULTS}/verification/pictures/shear_cell.png",
        verification_mu_series=f"{RESULTS}/verification/pictures/mu_series.png",
        segregation=f"{RESULTS}/application/segregation.csv",
        segregation_index=f"{RESULTS}/application/segregation_index.json",
        fig10=f"{RESULTS}/application/fig10_layout.png",
        fig11=f"{RESULTS}/application/fig11_segregation.png",
        # a sequential study also reports its rounds
        **({"rounds": f"{RESULTS}/sequential/rounds.md"} if SEQUENTIAL else {}),
