# A link length written in degrees.
robot farm {
    chain H1 - H3(link=45deg) - L1   # expect: error[wrong-unit] 'link' takes a length, not 'deg'
}
