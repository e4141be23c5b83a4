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


rule compared_controls:
    input:
        trajectories=lambda wildcards: [
            f"results/trajectories/{name}.h5" for name in config["pendulum"]["compare_controls"]
        ],
        code=code_inputs("mosys.cli.plots", "mosys.plots.controls"),  # mosys plot controls
    output:
        "results/plots/{group}/slew_torque.png",
    log:
        "results/logs/plots/{group}/slew_torque.log",
    benchmark:
        "results/benchmarks/plots/{group}/slew_torque.tsv"
    threads: 1
    shell:
        "mosys plot controls {input.trajectories} -o {output} 2> {log}"
        " || (cat {log} >&2; exit 1)"


rule free_swing:
    input:
        dynamics=lambda wildcards: f"results/dynamics/{config['pendulum']['figure']}.py",
        code=code_inputs("mosys.cli.plots", "mosys.plots.free_swing"),  # mosys plot free-swing
    output:
        "results/plots/{group}/free_swing.png",
    log:
        "results/logs/plots/{group}/free_swing.log",
    benchmark:
        "results/benchmarks/plots/{group}/free_swing.tsv"
    threads: 1
    shell:
        "NUMBA_NUM_THREADS={threads} mosys plot free-swing --dynamics {input.dynamics} -o {output}"
        " 2> {log} || (cat {log} >&2; exit 1)"
