"""Empirical references beside the DEM: the wheel-on-soil relations (VTI, WES, Brixius,
Wismer-Luth: wheel_numerics) and the NRMM-style speed prediction of a vehicle (nrmm)."""
