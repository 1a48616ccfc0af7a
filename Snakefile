# siloflow's workflow, run from a clone: plain `snakemake --cores 2` takes config/config.yaml unless --configfile names
# another. The workflow itself (its rules, scripts, schemas and report) is part of the package: siloflow/workflow/.


configfile: "config/config.yaml"


include: "siloflow/workflow/Snakefile"


# The included workflow's `all`, made this file's default target (a rule of the including file is the default).
rule default:
    input:
        rules.all.input,
    default_target: True
    localrule: True
