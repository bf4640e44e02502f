"""The virtual bulk tests: the Schulze shear cell and the lifted-cylinder angle of repose,
each with its set-up (derived quantities) and its readout (bulk values from engine output), and
the case directory of one run (:func:`demcal.virtual_tests.deck.render_case`).
"""
