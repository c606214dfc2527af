"""Experiments over many runs: sweep, push grid, push campaign, protocol, bench, the
capture bound they compare against, and the resumable job engine (:mod:`app.experiments.jobs`)."""
