"""The LTI 1.3 / LTI Advantage tool side of tpm-viz (``tpm-viz serve --lti CONFIG.toml``, docs/lti.md).

- :mod:`.config`: the configuration file (the tool's key, the platforms);
- :mod:`.keys`: the tool's RSA key, its ``kid`` and public JWKS, ``tpm-viz lti keygen``;
- :mod:`.platform_keys`: the platforms' key sets, fetched bounded and cached;
- :mod:`.refusals`: every refusal, with the word a lecturer looks for;
- :mod:`.logins`: the OIDC login (state, nonce) and its bounds;
- :mod:`.checks`: the ``id_token``'s checks;
- :mod:`.ledger`: the LTI records in the classroom store (users, the class's course, launches, the grade outbox);
- :mod:`.launches`: a checked launch turned into a user, a launch record and a one-time ticket;
- :mod:`.deeplinking`: the picker and the signed ``LtiDeepLinkingResponse``;
- :mod:`.tokens`, :mod:`.grades`: AGS access tokens and the scores sent back, exactly once in effect;
- :mod:`.pages`: the HTML the service answers with; :mod:`.service`: the Starlette app on uvicorn.

Layer rule (``tests/system/test_layering.py``): base, ``app/``, ``classroom/`` and ``lti/``, plus PyJWT,
cryptography, Starlette, uvicorn, httpx and python-multipart (the ``.[lti]`` extra); never viser.
"""
