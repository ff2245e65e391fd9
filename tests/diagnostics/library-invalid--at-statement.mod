# libraries/broken-epsilon.yaml gives the H actuator epsilon: 0, which the schema rejects.
robot farm {
    library "libraries/broken-epsilon.yaml"   # expect: error[library-invalid]
    chain H1 - L4(port=45deg) - L1
}
