# corpus-xfail: 1e307 rad is finite but math.degrees() of it overflows to inf; TwistSet._wrap() raises ValueError (math domain error)
robot farm {
    chain H1 - H4(port=1e307rad) - L4   # expect: error[twist-not-realisable]
}
