robot cellarm {
    chain H1 - L4(port=45deg) - L1
    target p1 at (0.3, 0.25) m   # expect: error[vector-arity] target 'p1' takes 3 values, got 2
}
