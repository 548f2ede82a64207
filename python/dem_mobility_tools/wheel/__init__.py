"""The single-wheel rig: its slip sweep (sweep, dm-wheel-sweep) and its plots (plots)."""
