# libraries/bench-3dof.yaml is Mark-2 with min_dof: 3.
robot bench {   # expect: error[too-few-units] the chain has 2 units; at least 3 are needed
    library "libraries/bench-3dof.yaml"
    chain H1 - L1
}
