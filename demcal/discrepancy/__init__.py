"""Discrepancy workflow: find where model and measurement disagree, name the missing effect
from a catalogue of candidates, add it and show the gap shrink.

The method: :mod:`.observations` (measured values, their uncertainty, surrogate predictions),
:mod:`.best_fit` (parameter box, minimisation), :mod:`.find` (Find), :mod:`.effect_response` and
:mod:`.ranking` (Name), :mod:`.candidates` (the catalogue and its cases), :mod:`.extension`
(Add). The steps on files, one per rule script: :mod:`.model_from_files` (Find),
:mod:`.probe_ranking` (Name), :mod:`.extension` and :mod:`.recalibration` (Add),
:mod:`.before_after` (Show); :mod:`.plan`, :mod:`.runs` and :mod:`.run_results` list, render and
read the DEM runs; :mod:`.report` formats tables, texts and the figure.
"""
