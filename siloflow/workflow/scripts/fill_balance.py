"""Snakemake adapter: the force balance of one run's settled fill, written as JSON; fails on a fill that is not
silo-like (see siloflow.analysis.numerics.force_balance)."""

from pathlib import Path

from siloflow.model.record import read_run_record
from siloflow.analysis.io.tables import write_json
from siloflow.analysis.numerics.force_balance import BalanceTolerances, balance_problems, settled_fill_balance
from siloflow.engines.interface import engine_named
from siloflow.engines.logs import logged_to

with logged_to(snakemake.log[0]) as log:
    run_dir = Path(snakemake.input.record).parent
    record = read_run_record(snakemake.input.record)
    balance_params = snakemake.params.balance
    heights = [fraction * balance_params["fill_height"] for fraction in balance_params["planes"]]
    settled = engine_named(record.engine).settled_fill(run_dir, record)
    balance = settled_fill_balance(settled, heights, balance_params["gravity"])
    tolerances = BalanceTolerances(**balance_params["tolerance"])
    problems = balance_problems(balance, tolerances)
    log.info("balance of %s: %s", record.run_id, balance.as_dict())
    write_json(snakemake.output.balance, {**balance.as_dict(), "run_id": record.run_id, "case": record.case,
                                          "tolerance": balance_params["tolerance"], "problems": problems})
    log.info("%s: walls + floor carry %.4f of the weight (floor %.3f, walls %+.3f); contacts / weight above %s",
             record.run_id, balance.support_ratio, balance.floor_ratio, balance.walls_ratio,
             ", ".join(f"{plane.contact_ratio:.3f} at {plane.height * 1e3:.0f} mm" for plane in balance.planes))
    if problems:
        # Snakemake deletes a failed job's outputs: the figures stay in this log and in the message
        raise RuntimeError(f"the settled fill of {record.case} run {record.run_id} fails its force balance "
                           f"(figures in {snakemake.log[0]}):\n- " + "\n- ".join(problems))
