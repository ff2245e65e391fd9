# A type-2 unit has no link module, so there is no port twist to set.
robot farm {
    chain H1 - H2(port=45deg) - L4   # expect: error[parameter-not-applicable] 'port' does not apply to H2: type 2 units have no link module
}
