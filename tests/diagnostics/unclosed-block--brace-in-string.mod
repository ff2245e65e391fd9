robot farm {
    library "libraries/}/mark2.yaml"
    chain H1 - L4(port=45deg) - L1
# expect-line 5: error[unclosed-block] the file ends inside robot block 'farm'
