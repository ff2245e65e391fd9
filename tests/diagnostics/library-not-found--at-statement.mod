# corpus-xfail: library diagnostics are reported at the robot's name, not at the `library` statement (lower.py drops library_span)
robot farm {
    library "nope.yaml"   # expect: error[library-not-found]
    chain H1 - L4(port=45deg) - L1
}
