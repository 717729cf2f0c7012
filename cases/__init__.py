"""The command line, case files, runs, results and renders (grows with the case-file issue)."""
