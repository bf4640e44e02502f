"""Virtual Schulze shear cell: set-up of the cell, the schedule of its Schulze sequence and
readout of mu_psh, mu_sh and rho_b.
"""
