"""The ``siloflow`` command (:func:`siloflow.cli.main.main`): its commands and their arguments, on top of the
engines' planning and the validation record; nothing else of siloflow imports it."""
