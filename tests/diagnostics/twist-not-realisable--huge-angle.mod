# corpus-xfail: 1e307 rad is finite but math.degrees() of it overflows to inf; TwistSet.nearest() then raises OverflowError (pivot) and _wrap() ValueError (port)
robot farm {
    chain H1 - H4(pivot=1e307rad) - L4   # expect: error[twist-not-realisable]
}
