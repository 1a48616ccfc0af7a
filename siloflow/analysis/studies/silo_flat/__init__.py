"""The flat-bottom silo study: discharge metrics (``metrics``), coarse-grained fields and profiles (``fields``),
comparison with measurements (``measured``) and figures (``plots``)."""
