# libraries/not-utf8.yaml cannot be decoded: no place in it to point at, so the diagnostic is at the statement.
robot farm {
    library "libraries/not-utf8.yaml"   # expect: error[library-invalid]
    chain H1 - L4(port=45deg) - L1
}
