"""Analyses on top of the simulator.

Identification (fit the model to measured data):

- :mod:`.data`: loaders and validation of bench data (:class:`~.data.DataError` on bad data),
  and the fitted parameter-file writer.
- :mod:`.kinetics_fit`: the wire's cosine phase kinetics (Eqs. 9-10) from strain-temperature
  curves under constant load.
- :mod:`.joint_fit`: heat-transfer and friction coefficients (h0, h2, C_DF) from the joint's
  angle-vs-time heating and cooling curves (the paper's Fig. 9), with the full simulator.
"""
