"""Workflow runs through real schedulers (a one-node Slurm cluster on localhost)."""
