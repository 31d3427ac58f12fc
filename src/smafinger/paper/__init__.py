"""The paper layer: the scenarios behind Gilardi et al. (2010)'s figures, their claims, the
runner of ``smafinger reproduce``, its figures and its report.

- :mod:`.scenarios`: the registry of named scenarios, figures and claims;
- :mod:`.claim`: a claim = a metric, a criterion and the paper's value;
- :mod:`.overrides`: typed changes to a scenario's run;
- :mod:`.investigation`: the readings of the Fig. 15 full-cycle gap, as data;
- :mod:`.runner`: :func:`reproduce`; :mod:`.figures` and :mod:`.report`: its outputs.
"""
