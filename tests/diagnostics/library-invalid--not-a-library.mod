# A `library` reference to a file that is not a module library: the message says what it is not
# and quotes none of it (an untrusted .mod could name /etc/passwd or a .env file).
robot farm { library "libraries/secrets.env"
    chain H1 - L4(port=45deg) - L1
}
# expect-line 3: error[library-invalid] module library 'libraries/secrets.env' is invalid: not a module library: it is plain text or a single value, not a YAML mapping
