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
    # the car's value iteration sweeps in two blocks side by side (README, "How controllers are
    # generated", step 3); the other grids are too small to split
    threads: lambda wildcards: 2 if wildcards.group == config["car"]["group"] else 1
    resources:
        # MiB: the car's table peaks at about 0.6 GiB (README, "The self-parking car"); every
        # other table at under 300 MiB (results/benchmarks/dp/*.tsv, max_rss)
        mem_mb=lambda wildcards: 2500 if wildcards.group == config["car"]["group"] else 1000,
        runtime=10,  # min: the car's takes under a minute, the others seconds
    priority: 3  # on the path to the script's plots: schedule first
    shell:
        "NUMBA_NUM_THREADS={threads} mosys dp {input.spec} --dynamics-dir results/dynamics -o {output} > {log} 2>&1"
