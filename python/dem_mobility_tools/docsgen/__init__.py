"""Generates the measured tables and plots of docs/ from the result files in docs/data/.

Each docs/data/*.yaml holds one table: the doc it belongs to, its marker, the provenance of the
figures (commit, machine, date, command) and the rows. `make.main` writes each table between
`<!-- generated: NAME -->` and `<!-- end generated -->` in its doc, and docs/launch.md from the
launch files' `<arg doc="...">` attributes; `--check` says which doc and table are out of date.
"""
