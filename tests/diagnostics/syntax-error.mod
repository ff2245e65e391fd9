# A target whose vector lost its closing parenthesis.
robot cell {
    chain H1 - L4(port=45deg) - L1
    target p1 at (0.3, 0, 0.25 m      # expect: error[syntax-error] unexpected 'm'; expected ')', ','
}
