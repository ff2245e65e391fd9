# libraries/broken-epsilon.yaml gives the H actuator epsilon: 0, which the schema rejects.
robot farm {
    library "libraries/broken-epsilon.yaml"
    chain H1 - L4(port=45deg) - L1
}
# the message is long: its expectation sits here, not on line 3
# expect-line 3: error[library-invalid] module library 'libraries/broken-epsilon.yaml' is invalid: variants.H.actuator.epsilon: Input should be greater than or equal to 1
