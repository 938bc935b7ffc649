"""The command layer: everything that exists because there is a command line.

Above the library, below only cli.py (and `python -m suds_exp`): parsers of option
strings into Python values (`campaign.parse_campaign_options`, `simulate.parse_freqs`,
`discrepancy.parse_exclude` ...), console printing (status, findings, stream summaries),
orchestration only the commands need (simulate then ingest), and the one translation of
library parameters into flags and library steps into commands (`messages`). Each
command's work is a function here or in the library, so a Python user can call it.
"""
