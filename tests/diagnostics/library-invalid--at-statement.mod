# corpus-xfail: library diagnostics are reported at the robot's name, not at the `library` statement (lower.py drops library_span)
# libraries/broken-epsilon.yaml gives the H actuator epsilon: 0, which the schema rejects.
robot farm {
    library "libraries/broken-epsilon.yaml"   # expect: error[library-invalid]
    chain H1 - L4(port=45deg) - L1
}
