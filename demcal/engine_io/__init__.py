"""Engine input/output: running a deck with the configured engine and reading what the
engine (or LIGGGHTS 3.8) writes: print files, dumps, VTK files and logs.
"""
