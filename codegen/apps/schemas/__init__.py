"""The schemas and the generated package as the commands find them: the package and its classes, a message by the
names a user gives it, the Markdown reference pages."""
