"""dem_mobility_tools: the Python side of dem_mobility (docs/sweeps.md, docs/doe.md).

Subpackages:
  sweep           the generic machinery of parameter sweeps: cases, a local pool, resume, progress
  terramechanics  empirical references: VTI, WES, Brixius, Wismer-Luth (wheel_numerics), NRMM (nrmm)
  doe             the design of experiments over grade x cone index and its maps (dm-doe)
  wheel           the single-wheel slip sweep and its plots (dm-wheel-sweep)
  calibration     the cone index calibration sweep (dm-calibrate)
  fidelity        the fidelity study of the vehicle on soil (dm-fidelity-study, dm-plot-fidelity)
  stability       the stability matrix (dm-stability)
  maps            the speed-made-good map on ROS (dm-publish-map) and the map benchmark
  plots           a run's speed (dm-plot-speed) and a compression test (dm-plot-compression)
  vehicle         the drive-shaft curves from the engine map (dm-driveshaft-curves)
  docsgen         the measured tables and plots of docs/ (dm-docs)
Modules:
  paths           the checkout, the build folder and the core runner dm_run_scene
  runs            one scene run's command for either runner, a free port, a run's result file
  launch          roslaunch with the exit status of the run it launched (dm-launch)
"""
