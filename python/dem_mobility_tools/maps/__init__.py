"""The speed-made-good map on ROS (publish, dm-publish-map) and the map benchmark (bench,
dm-bench-doe-map). The maps themselves are made by the doe subpackage (doe.maps)."""
