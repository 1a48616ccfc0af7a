# siloflow's workflow, run from a clone: plain `snakemake --cores 2` takes config/config.yaml unless --configfile names
# another. The workflow itself (its rules, scripts, schemas and report) is part of the package: siloflow/workflow/.


configfile: "config/config.yaml"


include: "siloflow/workflow/Snakefile"
