"""Sequential calibration: rounds of DEM runs placed where the measurements point.

Owns the choice of each round's parameter sets (:mod:`~demcal.sequential.proposal`), the
round records and the stopping rule (:mod:`~demcal.sequential.rounds`), the figure of the
rounds (:mod:`~demcal.sequential.figures`) and the comparison with one-shot designs
(:mod:`~demcal.sequential.comparison`). It consumes the design, the bulk dataset, the
surrogates and the identification; nothing below imports it.
"""
