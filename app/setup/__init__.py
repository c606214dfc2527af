"""From command-line names to a backend and a planner configuration: ``--set``
(:mod:`app.setup.overrides`), ``--paper-rules`` (:mod:`app.setup.paper_rules`) and the
build (:mod:`app.setup.build`)."""
