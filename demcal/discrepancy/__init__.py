"""Discrepancy workflow: find where model and measurement disagree, name the missing effect
from a catalogue of candidates, add it and show the gap shrink.
"""
