# Two commands do everything (see README): `make demo` and `make test`. Both set up what is missing first.
.PHONY: setup demo test check selftest bench
setup:
	bash tools/dev.sh setup
demo:
	bash tools/dev.sh demo out
test:
	bash tools/dev.sh test
check:
	bash tools/dev.sh check out/check
selftest:
	bash tools/dev.sh selftest out
bench:
	bash tools/dev.sh bench
