#!/usr/bin/python3
"""The Nsight Compute table of docs/performance.md from `tools/gpu_check.sh
profile`'s CSVs (one per benchmark game: ncu's metrics of one launch of the
stepping kernel, psc_run_kernel, over BATCH environments and STEPS steps).
Per environment-step figures divide by BATCH x STEPS.  With --kernel
psc_expand_kernel, the CSVs of `tools/gpu_check.sh expandprofile` (one
launch of search's expansion, BATCH children, STEPS 1): figures a child.

    bench/ncu_table.py FOLDER [--batch 131072] [--steps 8] [--kernel psc_run_kernel]
"""
import argparse
import csv
import glob
import os


def read_metrics(path, kernel):
    """Metric name -> value (float, units as ncu's --print-units base gives them)."""
    rows = []
    with open(path, errors="replace") as f:
        lines = [line for line in f if line.startswith('"')]  # psc bench's own lines are not CSV
    for row in csv.DictReader(lines):
        if kernel in row.get("Kernel Name", ""):
            rows.append(row)
    values = {}
    for row in rows:
        text = row.get("Metric Value", "").replace(",", "")
        try:
            values[row["Metric Name"]] = float(text)
        except ValueError:
            pass
    return values


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("folder")
    parser.add_argument("--batch", type=int, default=131072)
    parser.add_argument("--steps", type=int, default=8)
    parser.add_argument("--kernel", default="psc_run_kernel")
    args = parser.parse_args()
    env_steps = args.batch * args.steps
    unit = "a child" if args.kernel == "psc_expand_kernel" else "an env-step"
    print(f"| game | registers a thread | occupancy: achieved (theoretical) | issue slots busy | threads active a warp instruction (of 32) "
          f"| branch uniformity | thread instructions {unit} | local memory bytes {unit} | DRAM bytes {unit} "
          f"| kernel ns {unit} |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for path in sorted(glob.glob(os.path.join(args.folder, "*.csv"))):
        name = os.path.basename(path)[: -len(".csv")]
        m = read_metrics(path, args.kernel)
        if "gpu__time_duration.sum" not in m:
            print(f"| {name} | no metrics (see {name}.err) | | | | | | | | |")
            continue
        local = m.get("l1tex__t_bytes_pipe_lsu_mem_local_op_ld.sum", 0) + m.get("l1tex__t_bytes_pipe_lsu_mem_local_op_st.sum", 0)
        print(
            f"| {name} | {m.get('launch__registers_per_thread', 0):.0f} "
            f"| {m.get('sm__warps_active.avg.pct_of_peak_sustained_active', 0):.0f} % "
            f"({m.get('sm__maximum_warps_per_active_cycle_pct', 0):.0f} %) "
            f"| {m.get('smsp__issue_active.avg.pct_of_peak_sustained_active', 0):.0f} % "
            f"| {m.get('smsp__thread_inst_executed_per_inst_executed.ratio', 0):.1f} "
            f"| {m.get('smsp__sass_average_branch_targets_threads_uniform.pct', 0):.0f} % "
            f"| {m.get('smsp__thread_inst_executed.sum', 0) / env_steps:,.0f} "
            f"| {local / env_steps:,.0f} "
            f"| {m.get('dram__bytes.sum', 0) / env_steps:,.0f} "
            f"| {m['gpu__time_duration.sum'] / env_steps:,.2f} |"
        )


if __name__ == "__main__":
    main()
