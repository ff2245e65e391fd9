# libraries/broken-epsilon.yaml gives the H actuator epsilon: 0, which the library schema rejects.
robot farm { library "libraries/broken-epsilon.yaml"   # expect-in libraries/broken-epsilon.yaml:15: error[library-invalid]
    chain H1 - L4(port=45deg) - L1
}
