# A library number beyond its range is out-of-range at its line in the library file, as a .mod quantity is.
robot farm { library "libraries/huge-torque.yaml"   # expect-in libraries/huge-torque.yaml:14: error[out-of-range] variants.H.actuator.torque_peak = 1e+308 N·m is out of range (at most 1e+06 N·m)
    chain H1 - L4(port=45deg) - L1
}
