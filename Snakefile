# demcal: DEM contact-parameter calibration from bulk experiments.
# Table of contents: configuration, validation, the stages, and the default target.
from snakemake.utils import min_version

min_version("9.0")


configfile: "config/config.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/design.smk"


rule all:
    default_target: True
    input:
        design=DESIGN_TABLE,
