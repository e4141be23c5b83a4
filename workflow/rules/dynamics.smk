rule compile_dynamics:
    input:
        spec="specs/figures/{figure}.fig",
        code=code_inputs("mosys.cli.dynamics", "mosys.dynamics.compile"),  # mosys compile
    output:
        "results/dynamics/{figure}.py",
    log:
        "results/logs/dynamics/{figure}.log",
    benchmark:
        "results/benchmarks/dynamics/{figure}.tsv"
    priority: 3  # on the path to the script's plots: schedule first
    shell:
        "mosys compile {input.spec} -o {output} > {log} 2>&1"
