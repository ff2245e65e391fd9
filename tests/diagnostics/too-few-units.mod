# libraries/bench-3dof.yaml is Mark-2 with min_dof: 3.
robot bench {   # expect: error[too-few-units]
    library "libraries/bench-3dof.yaml"
    chain H1 - L1
}
