"""The child definition's defaults and limits, apart from the binding code so that the command
line can show them without importing the kernels."""

MAX_CHILDREN = 10_000_000
MAX_LENGTH_VARIATION = 0.9
MAX_FRIZZ = 0.5
DEFAULT_K = 4  # guides per child
DEFAULT_LENGTH_VARIATION = 0.1  # child lengths × [1 − v, 1 + v]
DEFAULT_FRIZZ = 0.01  # curl radius at the tip / child length
