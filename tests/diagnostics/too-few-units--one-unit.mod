# One unit below a minimum of three: the count is singular.
robot bench {   # expect: error[too-few-units] the chain has 1 unit; at least 3 are needed
    library "libraries/bench-3dof.yaml"
    allow first-variant
    chain L1
}
