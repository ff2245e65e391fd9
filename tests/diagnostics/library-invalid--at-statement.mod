# libraries/not-utf8.yaml cannot be decoded: no place in it to point at, so the diagnostic is at the statement.
robot farm {
    library "libraries/not-utf8.yaml"
    chain H1 - L4(port=45deg) - L1
}
# the message is long: its expectation sits here, not on line 3
# expect-line 3: error[library-invalid] module library 'libraries/not-utf8.yaml' is invalid: not a module library: it is not UTF-8 text (at byte 145)
