# Convenience wrapper around run.sh (the README's commands use run.sh, which
# needs nothing but bash on a fresh Debian machine).
.PHONY: demo test build deps bench clean
demo test build deps bench:
	./run.sh $@
clean:
	rm -rf build demo_output
