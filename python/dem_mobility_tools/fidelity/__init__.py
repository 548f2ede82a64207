"""The fidelity study of the vehicle on soil (study, dm-fidelity-study) and its plot from a file of
measured runs (plot, dm-plot-fidelity)."""
