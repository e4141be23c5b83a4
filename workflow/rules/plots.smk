rule controller_plots:
    input:
        table="results/controllers/{group}/{name}.h5",
        dynamics=lambda wildcards: f"results/dynamics/{config['pendulum']['figure']}.py",
        code=code_inputs("mosys.cli.plots", "mosys.plots.pendulum", "mosys.dynamics.load"),  # mosys plot controller
    output:
        portrait="results/plots/{group}/{name}_portrait.png",
        torque="results/plots/{group}/{name}_torque.png",
    log:
        "results/logs/plots/{group}/{name}.log",
    benchmark:
        "results/benchmarks/plots/{group}/{name}.tsv"
    threads: 1
    shell:
        "NUMBA_NUM_THREADS={threads} mosys plot controller {input.table} --dynamics {input.dynamics}"
        " --portrait {output.portrait} --torque {output.torque} 2> {log}"
        " || (cat {log} >&2; exit 1)"


rule script_plots:
    input:
        trajectory="results/trajectories/{script}.h5",
        tables=lambda wildcards: [p for p in script_inputs(wildcards) if p.endswith(".h5")],
        code=code_inputs("mosys.cli.plots", "mosys.plots.pendulum"),  # mosys plot script
    output:
        path="results/plots/{group}/{script}_path.png",
        gif="results/plots/{group}/{script}.gif",
    log:
        "results/logs/plots/{group}/{script}.log",
    benchmark:
        "results/benchmarks/plots/{group}/{script}.tsv"
    threads: 1
    priority: 1  # on the path to the script's plots: schedule first
    shell:
        "NUMBA_NUM_THREADS={threads} mosys plot script {input.trajectory} {input.tables}"
        " --path {output.path}"
        " --gif {output.gif} 2> {log} || (cat {log} >&2; exit 1)"
