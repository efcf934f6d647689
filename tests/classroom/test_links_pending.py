"""Share links in URLs (tpm_viz.classroom.links): the query a page is asked with, and the tokens waiting for their tab
(bounded in number, per address and in time, each read once)."""

from __future__ import annotations

from urllib.parse import parse_qs, urlsplit

from tpm_viz.classroom.links import MAX_TOKEN_CHARS, PendingLinks, share_url, token_of_query


class Clock:
    def __init__(self) -> None:
        self.now = 1000.0

    def __call__(self) -> float:
        return self.now


def test_the_link_is_the_page_url_with_the_token_in_its_query():
    url = share_url("http://192.0.2.7:8080/", "1.abc_-.0123456789abcdef")
    parts = urlsplit(url)
    assert (parts.scheme, parts.netloc, parts.path) == ("http", "192.0.2.7:8080", "/")
    assert parse_qs(parts.query) == {"share": ["1.abc_-.0123456789abcdef"]}  # read back by the standard library
    assert token_of_query(parts.query) == "1.abc_-.0123456789abcdef"


def test_a_query_without_share_is_no_link_and_a_huge_or_odd_one_is_kept_cut():
    assert token_of_query("") is None and token_of_query("lang=ko&x=1") is None
    assert token_of_query("share=") == ""  # present but empty: refused in the tab, not ignored
    assert token_of_query("share=a%20b&share=second") == "a b"  # the first value, decoded as browsers encode it
    assert len(token_of_query("share=" + "A" * (3 * MAX_TOKEN_CHARS)) or "") <= MAX_TOKEN_CHARS + 64
    assert token_of_query("&".join(f"k{i}=1" for i in range(100)) + "&share=x") == ""  # a flood of fields


def test_a_token_is_read_once_and_only_within_its_time():
    clock = Clock()
    links = PendingLinks(seconds=120.0, clock=clock)
    nonce = links.put("token-1", "192.0.2.1")
    assert len(nonce) >= 20 and nonce != links.put("token-1", "192.0.2.1")  # random, not derived from the token
    assert links.take(nonce) == "token-1" and links.take(nonce) is None
    late = links.put("token-2", "192.0.2.1")
    clock.now += 120.5
    assert links.take(late) is None and links.take(None) is None and links.take("") is None
    assert len(links) == 0


def test_one_address_cannot_push_out_the_class_and_the_whole_is_bounded():
    links = PendingLinks(most=20, per_address=3, clock=Clock())
    others = [links.put(f"class-{i}", f"192.0.2.{i}") for i in range(10)]
    flood = [links.put(f"flood-{i}", "198.51.100.9") for i in range(1000)]
    assert len(links) == 13  # ten students' and the flooder's last three
    assert [links.take(n) for n in flood[-3:]] == ["flood-997", "flood-998", "flood-999"]
    assert links.take(flood[0]) is None
    assert [links.take(n) for n in others] == [f"class-{i}" for i in range(10)]
    many = PendingLinks(most=20, per_address=3, clock=Clock())
    for i in range(100):
        many.put(f"t{i}", f"10.0.0.{i}")
    assert len(many) == 20
