rule pendulum_table:
    input:
        tables=pendulum_controller_tables(),
        dynamics=f"results/dynamics/{config['pendulum']['figure']}.py",
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.pendulum"),  # mosys pendulum-table
    output:
        csv=report("results/tables/pendulum_controllers.csv", caption="../report/pendulum_table.rst", category="1990 paper — the pendulum", subcategory="Figure 13"),
        md="results/tables/pendulum_controllers.md",
    log:
        "results/logs/tables/pendulum_controllers.log",
    benchmark:
        "results/benchmarks/tables/pendulum_controllers.tsv"
    params:
        budget=config["budget"],
    threads: 1
    priority: 1  # a long job: start it before the plots that can fill in around it
    shell:
        "NUMBA_NUM_THREADS={threads} mosys pendulum-table {input.tables} --dynamics {input.dynamics}"
        " --budget {params.budget}"
        " --csv {output.csv} --md {output.md} > {log} 2>&1"
