# The self-parking car (1990 paper, section 6): its start grid, its plots and its table. The
# controller and the Figure 19 trajectories come from the generic dp_controller and run_script.
rule car_start_grid:
    input:
        table=car_table(),
        dynamics=f"results/dynamics/{config['car']['figure']}.py",
        code=code_inputs(
            "mosys.cli.ssc",
            "mosys.dynamics.load",
            "mosys.io.start_grid",
            "mosys.ssc.controller",
            "mosys.ssc.parking",
        ),  # mosys starts
    output:
        "results/car/start_grid.h5",
    log:
        "results/logs/car/start_grid.log",
    benchmark:
        "results/benchmarks/car/start_grid.tsv"
    resources:
        mem_mb=2500,  # MiB: the car's table and its lookahead arrays (README)
        runtime=20,  # min: the shipped grid takes about 6 s on 2 cores
    params:
        x=" ".join(str(v) for v in config["car"]["start_grid"]["x"]),
        y=" ".join(str(v) for v in config["car"]["start_grid"]["y"]),
        heading=" ".join(str(v) for v in config["car"]["start_grid"]["heading"]),
        steer=" ".join(str(v) for v in config["car"]["start_grid"]["steer"]),
        seconds=config["car"]["start_grid"]["seconds"],
        dt=config["car"]["start_grid"]["dt"],
    threads: 2
    shell:
        "NUMBA_NUM_THREADS=1 mosys starts {input.table} --dynamics {input.dynamics}"
        " --x {params.x} --y {params.y} --heading {params.heading} --steer {params.steer}"
        " --seconds {params.seconds} --dt {params.dt} --threads {threads} -o {output} > {log} 2>&1"


rule car_frames:
    input:
        trajectories=car_trajectories(),
        code=code_inputs("mosys.cli.plots", "mosys.plots.car"),  # mosys plot car
    output:
        report("results/plots/car/figure19_frames.png", caption="../report/car_frames.rst", category="1990 paper — the self-parking car"),
    log:
        "results/logs/plots/car/figure19_frames.log",
    benchmark:
        "results/benchmarks/plots/car/figure19_frames.tsv"
    threads: 1
    shell:
        "mosys plot car {input.trajectories} --frames {output} > {log} 2>&1"


rule car_gif:
    input:
        trajectory=f"results/trajectories/{config['car']['gif_script']}.h5",
        code=code_inputs("mosys.cli.plots", "mosys.plots.car"),  # mosys plot car
    output:
        report("results/plots/car/manoeuvre.gif", caption="../report/car_gif.rst", category="1990 paper — the self-parking car"),
    log:
        "results/logs/plots/car/manoeuvre.log",
    benchmark:
        "results/benchmarks/plots/car/manoeuvre.tsv"
    threads: 1
    shell:
        "mosys plot car {input.trajectory} --gif {output} > {log} 2>&1"


rule car_start_map:
    input:
        grid="results/car/start_grid.h5",
        code=code_inputs("mosys.cli.plots", "mosys.plots.car_starts"),  # mosys plot car
    output:
        report("results/plots/car/start_map.png", caption="../report/car_map.rst", category="1990 paper — the self-parking car"),
    log:
        "results/logs/plots/car/start_map.log",
    benchmark:
        "results/benchmarks/plots/car/start_map.tsv"
    threads: 1
    shell:
        "mosys plot car --map {input.grid} {output} > {log} 2>&1"


rule car_consistency:
    input:
        grid="results/car/start_grid.h5",
        code=code_inputs("mosys.cli.plots", "mosys.plots.car_starts"),  # mosys plot car
    output:
        report("results/plots/car/consistency.png", caption="../report/car_consistency.rst", category="1990 paper — the self-parking car"),
    log:
        "results/logs/plots/car/consistency.log",
    benchmark:
        "results/benchmarks/plots/car/consistency.tsv"
    threads: 1
    shell:
        "mosys plot car --consistency {input.grid} {output} > {log} 2>&1"


rule car_controller_table:
    input:
        table=car_table(),
        grid="results/car/start_grid.h5",
        trajectories=car_trajectories(),
        code=code_inputs("mosys.cli.paper_tables", "mosys.paper_tables.car"),  # mosys car-table
    output:
        csv=report("results/tables/car_controller.csv", caption="../report/car_table.rst", category="1990 paper — the self-parking car"),
        md="results/tables/car_controller.md",
    log:
        "results/logs/tables/car_controller.log",
    benchmark:
        "results/benchmarks/tables/car_controller.tsv"
    params:
        budget=config["car"].get("budget", config["budget"]),  # ci.yaml: the paper's
    threads: 1
    shell:
        "mosys car-table {input.table} --starts {input.grid} --trajectories {input.trajectories}"
        " --budget {params.budget} --csv {output.csv} --md {output.md} > {log} 2>&1"
