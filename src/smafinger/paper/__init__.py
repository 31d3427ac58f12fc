"""The paper layer: the scenarios behind Gilardi et al. (2010)'s figures, their claims, the
runner of ``smafinger reproduce``, its figures and its report.

- :mod:`.scenarios`: the registry of named scenarios, figures and claims;
- :mod:`.claim`: a claim = a metric, a criterion and the paper's value;
- :mod:`.overrides`: typed changes to a scenario's run;
- :mod:`.investigation`: smafinger 0.1's readings of the Fig. 15 full-cycle gap, as data;
- :mod:`.studies`: scenarios re-run with one change each (issue 10's before/after and step-size
  check, the damping rules, thermal readings); :mod:`.issue10` and :mod:`.cycle_findings`: their
  tables, report sections and computed findings;
- :mod:`.runner`: :func:`reproduce`; :mod:`.figures` and :mod:`.report`: its outputs.
"""
