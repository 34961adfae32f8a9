"""Generated URDFs of the built-in arms (data only).

Every ``*.urdf`` here is generated from ``robots/xacro/<name>.urdf.xacro`` by
``pinarms urdf build`` and committed so that other tools can use it without pinarms.
Do not edit them by hand: the test suite fails when one differs from its xacro source.
"""
