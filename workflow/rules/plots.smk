# Pendulum-style drawings: every controller's portrait and torque map (any group: a table with
# more than two state dimensions is refused by the plot, with its reason), and the pendulum
# group's scripts, torque comparison and free swing.
PENDULUM_GROUP = re.escape(config["pendulum"]["group"])


rule controller_plots:
    input:
        table="results/controllers/{group}/{name}.h5",
        dynamics=plotted_controller_dynamics,
        code=code_inputs("mosys.cli.plots", "mosys.plots.controller", "mosys.dynamics.load"),  # mosys plot controller
    output:
        portrait=report("results/plots/{group}/{name}_portrait.png", caption="../report/portrait.rst", category="1990 paper — the pendulum", subcategory="Figure 14 portraits"),
        torque=report("results/plots/{group}/{name}_torque.png", caption="../report/torque.rst", category="1990 paper — the pendulum", subcategory="torque tables"),
    log:
        "results/logs/plots/{group}/{name}.log",
    benchmark:
        "results/benchmarks/plots/{group}/{name}.tsv"
    threads: 1
    shell:
        "NUMBA_NUM_THREADS={threads} mosys plot controller {input.table} --dynamics {input.dynamics}"
        " --portrait {output.portrait} --torque {output.torque} > {log} 2>&1"


rule script_plots:
    wildcard_constraints:
        group=PENDULUM_GROUP,  # the pendulum's drawings; the car and Luxo have their own
    input:
        trajectory="results/trajectories/{script}.h5",
        tables=lambda wildcards: [p for p in script_inputs(wildcards) if p.endswith(".h5")],
        code=code_inputs("mosys.cli.plots", "mosys.plots.script"),  # mosys plot script
    output:
        path=report("results/plots/{group}/{script}_path.png", caption="../report/script_path.rst", category="1990 paper — the pendulum", subcategory="scripts"),
        gif=report("results/plots/{group}/{script}.gif", caption="../report/script_gif.rst", category="1990 paper — the pendulum", subcategory="scripts"),
    log:
        "results/logs/plots/{group}/{script}.log",
    benchmark:
        "results/benchmarks/plots/{group}/{script}.tsv"
    threads: 1
    priority: 1  # on the path to the script's plots: schedule first
    shell:
        "NUMBA_NUM_THREADS={threads} mosys plot script {input.trajectory} {input.tables}"
        " --path {output.path}"
        " --gif {output.gif} > {log} 2>&1"


rule compared_controls:
    wildcard_constraints:
        group=PENDULUM_GROUP,  # the pendulum's drawings; the car and Luxo have their own
    input:
        trajectories=lambda wildcards: [
            f"results/trajectories/{name}.h5" for name in config["pendulum"]["compare_controls"]
        ],
        code=code_inputs("mosys.cli.plots", "mosys.plots.controls"),  # mosys plot controls
    output:
        report("results/plots/{group}/slew_torque.png", caption="../report/slew_torque.rst", category="1990 paper — the pendulum", subcategory="scripts"),
    log:
        "results/logs/plots/{group}/slew_torque.log",
    benchmark:
        "results/benchmarks/plots/{group}/slew_torque.tsv"
    threads: 1
    shell:
        "mosys plot controls {input.trajectories} -o {output} > {log} 2>&1"


rule free_swing:
    wildcard_constraints:
        group=PENDULUM_GROUP,  # the pendulum's drawings; the car and Luxo have their own
    input:
        dynamics=lambda wildcards: f"results/dynamics/{config['pendulum']['figure']}.py",
        code=code_inputs("mosys.cli.plots", "mosys.plots.free_swing"),  # mosys plot free-swing
    output:
        report("results/plots/{group}/free_swing.png", caption="../report/free_swing.rst", category="1990 paper — the pendulum", subcategory="Figure 5"),
    log:
        "results/logs/plots/{group}/free_swing.log",
    benchmark:
        "results/benchmarks/plots/{group}/free_swing.tsv"
    threads: 1
    shell:
        "NUMBA_NUM_THREADS={threads} mosys plot free-swing --dynamics {input.dynamics} -o {output} > {log} 2>&1"
