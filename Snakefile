# demcal: DEM contact-parameter calibration from bulk experiments.
# Table of contents: configuration, validation, the stages, and the default target.
from snakemake.utils import min_version

min_version("9.0")


configfile: "config/config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/design.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/bulk.smk"
include: "workflow/rules/surrogate.smk"
include: "workflow/rules/identify.smk"


rule all:
    default_target: True
    input:
        design=DESIGN_TABLE,
        dataset=DATASET,
        table4=f"{RESULTS}/surrogates/table4.md",
        table5=f"{RESULTS}/identification/table5.md",
        verification=f"{RESULTS}/verification/verification.md",
