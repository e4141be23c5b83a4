rule dp_controller:
    input:
        spec="specs/controllers/{group}/{name}.ssc",
        dynamics=controller_dynamics,
        code=code_inputs(
            "mosys.cli.ssc",
            "mosys.dynamics.load",
            "mosys.parsing.controller",
            "mosys.ssc.generate",
        ),  # mosys dp
    output:
        "results/controllers/{group}/{name}.h5",
    log:
        "results/logs/dp/{group}/{name}.log",
    benchmark:
        "results/benchmarks/dp/{group}/{name}.tsv"
    threads: 1
    priority: 3  # on the path to the script's plots: schedule first
    shell:
        "NUMBA_NUM_THREADS={threads} mosys dp {input.spec} --dynamics-dir results/dynamics -o {output} 2> {log}"
        " || (cat {log} >&2; exit 1)"
