"""The defaults of a run, in one place for the code, the command line's help texts and the docs
(tests/test_defaults.py compares all three). Plain numbers, no import: ``daeclear --help`` stays quick."""

#: ``SolverOptions.rtol``: IDA's relative tolerance (Table 4.2's integration tolerance).
RTOL = 1e-6
#: ``SolverOptions.max_steps``: the API's cap on a run's steps.
MAX_STEPS = 5_000_000
#: GGL (stabilised index 2) holds the joints closed to Newton's tolerance, so contact times converge
#: with rtol at any clearance; index-1 Baumgarte drifts (docs/engine.md).
FORMULATION = "ggl"
#: ``SaveAt.max_points``: the most output points a run reports unless told otherwise, about 1 GB for the
#: chapter's slider-crank, so a mistyped spacing is refused instead of filling a disk.
MAX_OUTPUT_POINTS = 1_000_000

#: ``daeclear run`` reports at most CLI_POINTS + 1 points by default, spaced no finer than
#: CLI_FINEST_STEP (s: each impact's peak force within 0.5 % of a grid 8 times finer).
CLI_POINTS = 100_000
CLI_FINEST_STEP = 2e-6
#: ``daeclear run``'s step cap: this many per simulated second, at least MAX_STEPS.
CLI_STEPS_PER_SECOND = 2_000_000
#: ``daeclear run`` shows (summary, figure) at most this many of the last events of a run (the file has all).
CLI_SHOWN_EVENTS = 20_000
#: ``daeclear run``'s figure draws at most this many points a curve (min-max per bucket: peaks survive).
CLI_FIGURE_POINTS = 2000
