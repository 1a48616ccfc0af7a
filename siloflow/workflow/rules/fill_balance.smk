# The settled fill's force balance of every run (flat-bottom silo, recirculating silo, blender, and the Jenike cell's
# levelled sample before its lid): the load the floor and each wall carry and the load across horizontal planes,
# against the weight. A fill that is not at rest, or whose planes carry more than the weight above, stops the
# pipeline here with a message that says so.

#: The case kinds whose registry entry asks for the balance.
FILL_BALANCE_CASES = tuple(name for name, kind in CASE_KINDS.items() if kind.fill_balance)


def fill_balance_params(kind):
    """The balance's parameters of one run of ``kind``: its fill height, gravity, the plane fractions and the tolerances."""
    def params(wildcards):
        fill = config[kind]["fill"]
        case = cases(kind)[wildcards.run]
        return {"fill_height": case.fill_height, "gravity": case.gravity, "planes": fill["balance_planes"],
                "tolerance": fill["balance_tolerance"]}
    return params


for _kind in FILL_BALANCE_CASES:

    rule:
        name:
            f"{_kind}_fill_balance"
        input:
            record=run_rule_output(_kind),
        output:
            balance=run_path(_kind, "metrics/fill_balance.json"),
        params:
            balance=fill_balance_params(_kind),
        log:
            run_path(_kind, "logs/fill_balance.log"),
        script:
            "../scripts/fill_balance.py"
