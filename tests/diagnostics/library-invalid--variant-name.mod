# A library's variant names are identifiers (letters only); libraries/bad-variant-name.yaml names one L'.
robot farm { library "libraries/bad-variant-name.yaml"   # expect-in libraries/bad-variant-name.yaml:46: error[library-invalid] module library 'libraries/bad-variant-name.yaml' is invalid: variants.L': "'" (character 2) is not allowed in a variant name
    chain H1 - H4(port=45deg) - H1
}
