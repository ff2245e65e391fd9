# The smallest useful arm: the chain from SPEC section 4.
robot farm {
    chain H1 - L4(port=45deg) - L1
}
