# Library text (descriptions, actuator models) holds no control characters: libraries/bad-description.yaml has a line break.
robot farm { library "libraries/bad-description.yaml"   # expect-in libraries/bad-description.yaml:15: error[library-invalid]
    chain H1 - L4(port=45deg) - L1
}
