"""Robustness of the engine against malformed decks: the project's own decks, mutated
(dropped, duplicated and swapped lines, bad numbers, stray tokens), run and classified. It
consumes the virtual tests' and the application's decks, so it sits above them.
"""
