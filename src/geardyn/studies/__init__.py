"""Studies: the paper's case study (:mod:`geardyn.studies.paper`) and parameter sweeps."""
