# Stage 3: all bulk values in one tidy table (one row per case and load condition) and the run
# times of the DEM cases.


if not SEQUENTIAL:
    # (a sequential study writes the dataset after its last round: sequential.smk)
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


rule run_times:
    input:
        benchmarks=lambda wildcards: [
            CASE_BENCHMARK.format(stage="cases", test=test, case=case)
            for test in TESTS
            for case in study_case_ids(test)
        ],
    output:
        table=report(
            f"{RESULTS}/bulk/run_times.csv", category="Runs", caption="../report/run_times.rst"
        ),
        figure=report(
            f"{RESULTS}/bulk/run_times.png", category="Runs", caption="../report/run_times.rst"
        ),
    log:
        f"{LOGS}/bulk/run_times.log",
    localrule: True
    conda:
        CONDA_ENV
    script:
        "../../scripts/run_times.py"
