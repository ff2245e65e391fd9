# The `chain` keyword was forgotten.
robot farm {
    H1 - L4(port=45deg) - L1   # expect: error[expected-statement] expected a statement, found 'H1'
}
