# Convenience wrapper around run.sh (the README's commands use run.sh, which
# needs nothing but bash on a fresh Debian machine).
.PHONY: demo test test-sanitize build deps bench clean
demo test test-sanitize build deps bench:
	./run.sh $@
clean:
	rm -rf build build-sanitize demo_output
