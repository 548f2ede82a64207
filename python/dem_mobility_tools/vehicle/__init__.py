"""Vehicle data derived from the reference: the drive-shaft curves (driveshaft_curves,
dm-driveshaft-curves)."""
