# libraries/broken-epsilon.yaml gives the H actuator epsilon: 0, which the library schema rejects.
robot farm { library "libraries/broken-epsilon.yaml"
    chain H1 - L4(port=45deg) - L1
}
# the diagnostic points into the library file; its message is long, so the expectation sits here
# expect-in libraries/broken-epsilon.yaml:15: error[library-invalid] module library 'libraries/broken-epsilon.yaml' is invalid: variants.H.actuator.epsilon: must be at least 1
