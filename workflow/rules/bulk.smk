# Stage 3: all bulk values in one tidy table (one row per case and load condition).


rule collect_dataset:
    input:
        bulk=[
            f"{RESULTS}/cases/{test}/{case}/bulk.csv" for test in TESTS for case in CASES[test]
        ],
    output:
        dataset=report(DATASET, category="Bulk values", caption="../report/dataset.rst"),
        failed=report(
            f"{RESULTS}/bulk/failed_cases.csv",
            category="Bulk values",
            caption="../report/failed_cases.rst",
        ),
    log:
        f"{LOGS}/bulk/collect_dataset.log",
    resources:
        runtime=resource("analysis", "runtime", 10),
    conda:
        CONDA_ENV
    script:
        "../../scripts/collect_dataset.py"
