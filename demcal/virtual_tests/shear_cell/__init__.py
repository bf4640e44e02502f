"""Virtual Schulze shear cell: set-up of the cell and readout of mu_psh, mu_sh and rho_b.
"""
