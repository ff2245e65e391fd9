# A library path is resolved relative to this file; there is no nope.yaml next to it.
robot farm { library "nope.yaml"   # expect: error[library-not-found] module library 'nope.yaml' not found
    chain H1 - L4(port=45deg) - L1
}
