"""Identification: acceptance rule, screening of the candidate grid, statistics of the valid
sets (Table 5), figures and the verification of the identified set.
"""
