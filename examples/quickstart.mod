# The smallest useful arm: the chain of the language guide (docs/language.md).
robot farm {
    chain H1 - L4(port=45deg) - L1
}
