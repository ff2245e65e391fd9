# A library's variant names are identifiers (letters only); libraries/bad-variant-name.yaml names one L'.
robot farm { library "libraries/bad-variant-name.yaml"   # expect-in libraries/bad-variant-name.yaml:46: error[library-invalid]
    chain H1 - H4(port=45deg) - H1
}
