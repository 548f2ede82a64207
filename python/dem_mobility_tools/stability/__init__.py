"""The stability matrix: every scene pushed past its limits, each cell judged (matrix, dm-stability)."""
